// `trivox cluster slurm` (docs/CLUSTER.md): the scripts it writes, run here without Slurm as
// an array's tasks would run them (SLURM_ARRAY_TASK_ID set by hand), make the folder one run
// of the job makes; what it refuses. scripts/slurm_check.sh submits them to a real Slurm.
#include <sys/stat.h>

#include <filesystem>
#include <set>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// Every file of `ref` but stats.json has the same bytes in `dir`, which holds no other file
// but the shards' statistics (stats.shard-I-of-N.json: each run's own work) and the Slurm
// scripts and logs.
void expect_same_folder(const fs::path& ref, const fs::path& dir) {
  std::set<std::string> ref_files, dir_files;
  for (const auto& e : fs::recursive_directory_iterator(ref))
    if (e.is_regular_file() && e.path().filename() != "stats.json") ref_files.insert(fs::relative(e.path(), ref));
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    if (e.is_regular_file() && !name.starts_with("stats.") && !name.starts_with("slurm/") &&
        !name.starts_with(".trivox-cache/"))
      dir_files.insert(name);
  }
  for (const std::string& name : ref_files) {
    EXPECT_TRUE(dir_files.count(name)) << name << " is missing";
    if (dir_files.count(name)) {
      EXPECT_EQ(read_text(ref / name), read_text(dir / name)) << name;
    }
  }
  for (const std::string& name : dir_files) EXPECT_TRUE(ref_files.count(name)) << name << " is extra";
}

TEST(CliCluster, TheScriptsRunAsAnArraysTasksAndTheMergeMakeTheFolderOfOneRun) {
  ScratchDir dir;
  const fs::path scene = fs::canonical(examples_dir() / "scenes" / "quick_start.json");
  const fs::path out = dir.path() / "cluster", ref = dir.path() / "one";
  // gcvf, a stack format: the shards keep their layers, the merge task writes the package.
  const std::string options = "--layers 1:40 --min-layers 0 --dither blue-noise --format voxelprint gcvf";
  const CliResult written =
      run_cli(fmt::format("cluster slurm {} -o {} --shards 3 -j 1 {}", shell_quote(scene), shell_quote(out), options));
  ASSERT_EQ(written.exit_code, 0) << written.err;
  const fs::path shards = out / "slurm" / "shards.sbatch", merge = out / "slurm" / "merge.sbatch";
  EXPECT_NE(written.out.find(
                fmt::format("wrote {} and {}: 3 shards of 40 layers, 1 thread and ", shards.string(), merge.string())),
            std::string::npos)
      << written.out;
  EXPECT_NE(written.out.find(fmt::format("  a1=$(sbatch --parsable --array=1-3 {} 0)\n", shards.string())),
            std::string::npos)
      << written.out;
  EXPECT_NE(written.out.find(fmt::format("  sbatch --dependency=afterok:$a1 {}\n", merge.string())), std::string::npos)
      << written.out;
  for (const fs::path& s : {shards, merge})
    EXPECT_TRUE((fs::status(s).permissions() & fs::perms::owner_exec) != fs::perms::none);
  const std::string script = read_text(shards);
  // The job options as given, in the order `trivox slice --help` lists them.
  EXPECT_NE(script.find(" -j \"${SLURM_CPUS_PER_TASK:-1}\" --layers 1:40 --dither blue-noise --format voxelprint "
                        "--format gcvf --min-layers 0 &\n"),
            std::string::npos)
      << script;
  // The merge task writes the package from the layers the shards kept, with the job's options.
  EXPECT_NE(read_text(merge).find(fmt::format("slice {} -o {} --resume -j \"${{SLURM_CPUS_PER_TASK:-1}}\" --layers "
                                              "1:40 --dither blue-noise --format voxelprint --format gcvf",
                                              scene.string(), out.string())),
            std::string::npos)
      << read_text(merge);
  EXPECT_EQ(script.find("--shards"), std::string::npos) << script;

  const auto run_task = [&](int task) {
    const int status =
        std::system(fmt::format("SLURM_ARRAY_JOB_ID=77 SLURM_ARRAY_TASK_ID={} SLURM_CPUS_PER_TASK=1 bash {} 0", task,
                                shell_quote(shards))
                        .c_str());
    EXPECT_EQ(status, 0) << "task " << task;
  };
  run_task(1);
  run_task(3);
  // A shard that never ran: the merge names it and how to slice just it.
  const CliResult early = run_cli("merge " + shell_quote(out));
  EXPECT_EQ(early.exit_code, 3) << early.err;
  EXPECT_NE(early.err.find(fmt::format("cannot merge: shard(s) 2 of 3 have no manifest yet; slice each with `trivox "
                                       "slice {} -o {} --shard I/3 --resume`",
                                       scene.string(), out.string())),
            std::string::npos)
      << early.err;
  EXPECT_NE(early.err.find(fmt::format("or on Slurm `sbatch --array=2 {} 0`", shards.string())), std::string::npos)
      << early.err;
  run_task(2);
  EXPECT_NE(read_text(out / "slurm" / "shard-2.log").find("trivox: shard 2 of 3: task 77_2 on "), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "manifest.shard-3-of-3.json"));
  EXPECT_EQ(std::system(fmt::format("SLURM_JOB_ID=78 bash {} > {} 2>&1", shell_quote(merge),
                                    shell_quote(dir.path() / "merge.log"))
                            .c_str()),
            0)
      << read_text(dir.path() / "merge.log");
  EXPECT_NE(read_text(dir.path() / "merge.log").find("ok: 40 layers, 42 files match manifest.json"), std::string::npos)
      << read_text(dir.path() / "merge.log");

  const CliResult one = run_cli(fmt::format("slice {} -o {} -q {}", shell_quote(scene), shell_quote(ref), options));
  ASSERT_EQ(one.exit_code, 0) << one.err;
  expect_same_folder(ref, out);
}

TEST(CliCluster, RefusesAShardOfItsOwnAndAFolderThatHoldsAJob) {
  ScratchDir dir;
  const std::string scene = shell_quote(examples_dir() / "scenes" / "quick_start.json");
  const std::string out = shell_quote(dir.path() / "out");
  const CliResult shard = run_cli(fmt::format("cluster slurm {} -o {} --shards 2 --shard 1/2", scene, out));
  EXPECT_EQ(shard.exit_code, 2) << shard.err;
  EXPECT_NE(shard.err.find("--shard is set by the scripts"), std::string::npos) << shard.err;
  const CliResult no_shards = run_cli(fmt::format("cluster slurm {} -o {}", scene, out));
  EXPECT_EQ(no_shards.exit_code, 2) << no_shards.err;
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "slurm"));
  ASSERT_EQ(run_cli(fmt::format("slice {} -o {} -q --layers 1:3 --min-layers 0", scene, out)).exit_code, 0);
  const CliResult taken = run_cli(fmt::format("cluster slurm {} -o {} --shards 2", scene, out));
  EXPECT_EQ(taken.exit_code, 3) << taken.err;
  EXPECT_NE(taken.err.find("the folder holds a job already"), std::string::npos) << taken.err;
}

}  // namespace
}  // namespace trivox::test
