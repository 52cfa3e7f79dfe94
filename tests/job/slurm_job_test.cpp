// The Slurm batch scripts of a sharded job (include/trivox/job/slurm_job.h): the arrays that
// cover the shards, words quoted for bash, and scripts bash reads with the directives a
// cluster needs. tests/cli/cli_cluster_test.cpp runs the scripts without Slurm;
// scripts/slurm_check.sh submits them to a real one.
#include "trivox/job/slurm_job.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "trivox/error.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

TEST(SlurmJob, ArrayPartsCoverEveryShardOnceWithIndicesBelowMaxArraySize) {
  const auto parts_of = [](int shards, int max_array) {
    std::vector<std::pair<int, int>> out;
    for (const SlurmArrayPart& p : slurm_array_parts(shards, max_array)) out.emplace_back(p.offset, p.count);
    return out;
  };
  using V = std::vector<std::pair<int, int>>;
  EXPECT_EQ(parts_of(4, 1001), (V{{0, 4}}));
  EXPECT_EQ(parts_of(1000, 1001), (V{{0, 1000}}));
  EXPECT_EQ(parts_of(1001, 1001), (V{{0, 1000}, {1000, 1}}));
  EXPECT_EQ(parts_of(2500, 1001), (V{{0, 1000}, {1000, 1000}, {2000, 500}}));
  EXPECT_EQ(parts_of(5, 2), (V{{0, 1}, {1, 1}, {2, 1}, {3, 1}, {4, 1}}));
  EXPECT_THROW(slurm_array_parts(0, 1001), Error);
  EXPECT_THROW(slurm_array_parts(4, 1), Error);
  EXPECT_EQ(slurm_array_parts(1000, 2).size(), 1000u);
  EXPECT_THROW(slurm_array_parts(1000000, 2), Error);  // a million submissions
}

// What bash makes of `word` quoted by shell_word.
std::string through_bash(const std::string& word) {
  const fs::path script = fs::temp_directory_path() / fmt::format("trivox-shell-word-{}.sh", ::getpid());
  std::ofstream(script) << "printf '%s' " << shell_word(word) << "\n";
  std::string out;
  if (std::FILE* pipe = ::popen(("bash " + script.string()).c_str(), "r")) {
    char buffer[256];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
    ::pclose(pipe);
  }
  fs::remove(script);
  return out;
}

TEST(SlurmJob, EveryWordReadsBackThroughBashAsItself) {
  for (const std::string& word :
       {std::string("plain-word_1.json"), std::string("with space"), std::string("it's"), std::string("$HOME"),
        std::string("a\"b\\c"), std::string("new\nline"), std::string("*"), std::string("`id`"),
        std::string("--layers=1:40"), std::string("x;rm -rf y"), std::string("é ü")})
    EXPECT_EQ(through_bash(word), word) << shell_word(word);
  EXPECT_EQ(shell_word("plain-word_1.json"), "plain-word_1.json");
  EXPECT_EQ(shell_word(""), "''");
}

SlurmJobParams example_params() {
  SlurmJobParams p;
  p.program = "/opt/trivox/bin/trivox";
  p.scene = "/projects/lab a/part's scene.json";
  p.output_dir = "/shared/out";
  p.slice_args = {"--layers", "1:40", "--dither", "blue-noise"};
  p.shards = 3;
  p.cpus_per_task = 2;
  p.memory_mb = 500;
  p.time_minutes = 30;
  p.partition = "long";
  p.account = "lab";
  p.job_name = "trivox-part";
  return p;
}

bool bash_reads(const std::string& script) {
  const fs::path path = fs::temp_directory_path() / fmt::format("trivox-slurm-script-{}.sh", ::getpid());
  std::ofstream(path) << script;
  const int status = std::system(("bash -n " + path.string()).c_str());
  fs::remove(path);
  return status == 0;
}

TEST(SlurmJob, TheShardScriptAsksForWhatTheShardNeedsAndResumesItsShard) {
  const std::string s = slurm_shard_script(example_params());
  EXPECT_TRUE(bash_reads(s)) << s;
  EXPECT_EQ(s.rfind("#!/bin/bash\n", 0), 0u);
  for (const char* line :
       {"#SBATCH --job-name=trivox-part\n", "#SBATCH --partition=long\n", "#SBATCH --account=lab\n",
        "#SBATCH --cpus-per-task=2\n", "#SBATCH --mem=500M\n", "#SBATCH --time=30\n", "#SBATCH --requeue\n",
        "#SBATCH --signal=B:USR1@120\n", "#SBATCH --output=/shared/out/slurm/slurm-%A_%a.out\n",
        "shard=$((offset + SLURM_ARRAY_TASK_ID))\n", "exec >>/shared/out/slurm/shard-\"$shard\".log 2>&1\n",
        "trap stop_and_requeue USR1\n", "  scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n",
        "/opt/trivox/bin/trivox slice '/projects/lab a/part'\\''s scene.json' -o /shared/out --shard \"$shard/3\" "
        "--resume -j \"${SLURM_CPUS_PER_TASK:-2}\" --layers 1:40 --dither blue-noise &\n"})
    EXPECT_NE(s.find(line), std::string::npos) << line << "\nin\n" << s;
  // The partition's defaults where none is asked for.
  SlurmJobParams bare = example_params();
  bare.memory_mb = 0, bare.time_minutes = 0, bare.partition.clear(), bare.account.clear();
  const std::string b = slurm_shard_script(bare);
  for (const char* directive : {"--mem=", "--time=", "--partition=", "--account="})
    EXPECT_EQ(b.find(directive), std::string::npos) << directive;
}

TEST(SlurmJob, TheMergeScriptMergesThenVerifies) {
  const std::string s = slurm_merge_script(example_params());
  EXPECT_TRUE(bash_reads(s)) << s;
  const std::size_t merge = s.find("\n/opt/trivox/bin/trivox merge /shared/out\n");
  const std::size_t verify = s.find("\n/opt/trivox/bin/trivox verify /shared/out\n");
  ASSERT_NE(merge, std::string::npos) << s;
  ASSERT_NE(verify, std::string::npos) << s;
  EXPECT_LT(merge, verify);
  EXPECT_NE(s.find("set -eu\n"), std::string::npos);  // no verify after a failed merge
  EXPECT_NE(s.find("#SBATCH --job-name=trivox-part-merge\n"), std::string::npos);
  EXPECT_EQ(s.find("trivox slice"), std::string::npos) << s;  // no stack outputs to write
}

TEST(SlurmJob, AJobWithStackOutputsWritesThemAfterTheMergeAndOneShardOnlyVerifies) {
  SlurmJobParams p = example_params();
  p.stack_outputs = true;
  p.merge_memory_mb = 3000;
  std::string s = slurm_merge_script(p);
  EXPECT_TRUE(bash_reads(s)) << s;
  const std::size_t merge = s.find("\n/opt/trivox/bin/trivox merge /shared/out\n");
  const std::size_t resume = s.find(
      "\n/opt/trivox/bin/trivox slice '/projects/lab a/part'\\''s scene.json' -o /shared/out --resume -j "
      "\"${SLURM_CPUS_PER_TASK:-2}\" --layers 1:40 --dither blue-noise\n");
  const std::size_t verify = s.find("\n/opt/trivox/bin/trivox verify /shared/out\n");
  ASSERT_NE(resume, std::string::npos) << s;
  EXPECT_LT(merge, resume);
  EXPECT_LT(resume, verify);
  EXPECT_NE(s.find("#SBATCH --mem=3000M\n"), std::string::npos) << s;
  EXPECT_NE(s.find(fmt::format("#SBATCH --cpus-per-task={}\n", p.cpus_per_task)), std::string::npos) << s;
  // One shard is the whole job: it wrote manifest.json, so there is nothing to merge.
  p.shards = 1;
  s = slurm_merge_script(p);
  EXPECT_EQ(s.find("trivox merge"), std::string::npos) << s;
  EXPECT_EQ(s.find("trivox slice"), std::string::npos) << s;
  EXPECT_NE(s.find("\n/opt/trivox/bin/trivox verify /shared/out\n"), std::string::npos) << s;
}

}  // namespace
}  // namespace trivox
