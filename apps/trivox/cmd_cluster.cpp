// `trivox cluster slurm SCENE -o DIR --shards N`: the batch scripts of a sharded job on a
// Slurm cluster, and with --submit the sbatch calls (docs/CLUSTER.md).
#include <sys/stat.h>
#include <sys/vfs.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_checks.h"
#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "stop_signal.h"
#include "trivox/error.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/job_folder.h"
#include "trivox/job/job_lock.h"
#include "trivox/job/manifest.h"
#include "trivox/job/slice_job.h"
#include "trivox/job/slurm_job.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/layer_writer.h"
#include "trivox/scene/scene.h"

namespace trivox::cli {

namespace {

namespace fs = std::filesystem;

struct ClusterOptions {
  JobOptions job;
  int shards = 0;
  std::string partition, account;
  int time_minutes = 0;  // 0: from the estimate
  int memory_mb = 0;     // 0: from the estimate
  int max_array_size = 1001;
  bool submit = false;
};

// The options of the shard's `trivox slice` command line, word for word as given here: every
// job option that was set, except the scene, the folder and the threads, which the script sets
// itself. CLI11 keeps each option's words (results()), so nothing is re-spelled.
std::vector<std::string> slice_words(const CLI::App& cmd, const std::set<std::string>& own) {
  std::vector<std::string> words;
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt->count() == 0 || opt->get_positional()) continue;
    const std::string flag =
        opt->get_lnames().empty() ? "-" + opt->get_snames().front() : "--" + opt->get_lnames().front();
    if (own.count(flag)) continue;
    if (opt->get_expected_min() == 0) {
      words.push_back(flag);
      continue;
    }
    for (const std::string& value : opt->results()) {
      words.push_back(flag);
      words.push_back(value);
    }
  }
  return words;
}

// The file system's name when it is one only this machine sees (statfs magic numbers of the
// local kinds); empty for NFS, Lustre, GPFS, BeeGFS, CephFS and any other.
std::string local_file_system(const fs::path& dir) {
  struct statfs s {};
  if (::statfs(dir.c_str(), &s) != 0) return {};
  switch (static_cast<unsigned long>(s.f_type)) {
    case 0xEF53UL: return "ext4";
    case 0x58465342UL: return "xfs";
    case 0x9123683EUL: return "btrfs";
    case 0x01021994UL: return "tmpfs";
    case 0x794C7630UL: return "overlayfs";
    default: return {};
  }
}

// Runs a shell command line and returns its standard output; throws IoError naming it when it
// cannot start or exits non-zero.
std::string run_command(const std::string& line) {
  std::FILE* pipe = ::popen((line + " 2>&1").c_str(), "r");
  if (pipe == nullptr) throw IoError(fmt::format("cannot run `{}`", line));
  std::string out;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = ::pclose(pipe);
  if (status != 0) throw IoError(fmt::format("`{}` failed: {}", line, out.empty() ? "no output" : out));
  return out;
}

// Slurm's MaxArraySize from `scontrol show config`; `fallback` when it does not say.
int max_array_size_of_cluster(int fallback) {
  const std::string config = run_command("scontrol show config");
  const std::size_t at = config.find("MaxArraySize");
  if (at == std::string::npos) return fallback;
  const std::size_t eq = config.find('=', at);
  return eq == std::string::npos ? fallback : std::max(2, std::atoi(config.c_str() + eq + 1));
}

// The job id of an `sbatch --parsable` answer ("123" or "123;cluster").
std::string job_id_of(const std::string& answer) {
  std::string id = answer.substr(0, answer.find_first_of(";\n"));
  if (id.empty() || !std::all_of(id.begin(), id.end(), [](char c) { return c >= '0' && c <= '9'; }))
    throw IoError(fmt::format("sbatch answered '{}', not a job id", answer));
  return id;
}

void run_cluster_slurm(const CLI::App& cmd, const ClusterOptions& c) {
  const JobOptions& o = c.job;
  if (!o.shard.empty()) throw UsageError("--shard is set by the scripts: give the number of shards with --shards");
  JobParams job = job_params_of(o);
  const fs::path dir = fs::absolute(o.output).lexically_normal();
  if (auto problem = output_folder_problem(dir)) throw IoError(std::move(*problem));
  if (holds_job(dir))
    throw Error(fmt::format(
        "{}: the folder holds a job already (its manifests): slice into another folder; to rerun shards of that "
        "job, submit its own script again (docs/CLUSTER.md, \"When a shard fails\")",
        dir.string()));

  // The shard's cost, as the shard itself will estimate it: its memory sets --mem, its time
  // the default --time.
  job.shard_index = 1, job.shard_count = c.shards, job.threads = o.threads > 0 ? o.threads : 4;
  job.stop = stop_on_signals();
  const Scene scene = read_scene(o.scene, job.stop);
  const Slicer slicer(scene, slice_params_for(slice_params_of(o, scene), job));
  check_job_settings(slicer, job);  // what a shard would refuse, refused before anything is submitted
  const JobEstimate e = estimate_job(slicer, job, EstimateParams{1});
  SlurmJobParams p;
  std::error_code ec;
  p.program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw IoError(fmt::format("cannot find this program's path: {}", ec.message()));
  p.scene = fs::absolute(o.scene).lexically_normal();
  p.output_dir = dir;
  p.shards = c.shards, p.cpus_per_task = job.threads;
  p.partition = c.partition, p.account = c.account;
  p.slice_args = slice_words(cmd, {"--output", "--threads", "--shards", "--partition", "--account", "--time", "--mem",
                                   "--max-array-size", "--submit"});
  // A quarter more than the estimate and 256 MB for the shell and the loader.
  const auto task_memory_mb = [](const JobEstimate& estimate) {
    return static_cast<std::uint64_t>(std::ceil(static_cast<double>(estimate.peak_memory_bytes) * 1.25 / 1e6)) + 256;
  };
  p.memory_mb = c.memory_mb > 0 ? static_cast<std::uint64_t>(c.memory_mb) : task_memory_mb(e);
  p.time_minutes =
      c.time_minutes > 0 ? c.time_minutes : std::max(10, static_cast<int>(std::ceil(e.seconds * 3 / 60)) + 5);
  p.job_name = "trivox-" + fs::path(o.scene).stem().string();
  // Stack outputs are written after the merge by the whole job's resume, from the layers the
  // shards kept: its memory is the whole job's (a stack writer's grids, for one).
  p.stack_outputs =
      std::any_of(job.formats.begin(), job.formats.end(), [](const auto& f) { return is_stack_format(f); });
  if (p.stack_outputs) {
    JobParams whole = job;
    whole.shard_count = 1;
    const JobEstimate w = estimate_job(slicer, whole, EstimateParams{1});
    p.merge_memory_mb = task_memory_mb(w);
  }

  // The arrays, before anything is written: a job that needs too many is refused whole.
  const int max_array = c.submit ? max_array_size_of_cluster(c.max_array_size) : c.max_array_size;
  const std::vector<SlurmArrayPart> parts = slurm_array_parts(c.shards, max_array);
  fs::create_directories(dir / "slurm", ec);
  if (ec) throw IoError(fmt::format("{}: cannot create: {}", (dir / "slurm").string(), ec.message()));
  const fs::path shards_script = dir / "slurm" / "shards.sbatch", merge_script = dir / "slurm" / "merge.sbatch";
  write_file_atomic(shards_script, slurm_shard_script(p));
  write_file_atomic(merge_script, slurm_merge_script(p));
  for (const fs::path& s : {shards_script, merge_script}) ::chmod(s.c_str(), 0755);
  fmt::print("wrote {} and {}: {} shards of {} layers, {} and {} MB a task, time limit {} min\n",
             shards_script.string(), merge_script.string(), c.shards, e.model_layers + e.padded_layers,
             thread_text(p.cpus_per_task), p.memory_mb, p.time_minutes);
  if (const std::string fs_name = local_file_system(dir); !fs_name.empty())
    fmt::print(
        "note: {} is on a local file system ({}): only the nodes that mount it can run the shards (fine on "
        "a one-node cluster; docs/CLUSTER.md, \"The output folder\")\n",
        dir.string(), fs_name);

  if (!c.submit) {
    fmt::print("submit with:\n");
    for (std::size_t i = 0; i < parts.size(); ++i)
      fmt::print("  a{}=$(sbatch --parsable --array=1-{} {} {})\n", i + 1, parts[i].count,
                 shell_word(shards_script.string()), parts[i].offset);
    std::vector<std::string> deps;
    for (std::size_t i = 0; i < parts.size(); ++i) deps.push_back(fmt::format("$a{}", i + 1));
    fmt::print("  sbatch --dependency=afterok:{} {}\n", fmt::join(deps, ":"), shell_word(merge_script.string()));
    return;
  }
  std::vector<std::string> ids;
  for (const SlurmArrayPart& part : parts)
    ids.push_back(job_id_of(run_command(fmt::format("sbatch --parsable --array=1-{} {} {}", part.count,
                                                    shell_word(shards_script.string()), part.offset))));
  const std::string merge_id = job_id_of(run_command(fmt::format(
      "sbatch --parsable --dependency=afterok:{} {}", fmt::join(ids, ":"), shell_word(merge_script.string()))));
  fmt::print("submitted the shards as job{} {} and the merge as job {} (it starts when every shard has succeeded)\n",
             ids.size() == 1 ? "" : "s", fmt::join(ids, ", "), merge_id);
  fmt::print("watch: squeue -j {},{}; each shard's log: {}/slurm/shard-I.log\n", fmt::join(ids, ","), merge_id,
             dir.string());
}

}  // namespace

void add_cluster_command(CLI::App& app) {
  auto opts = std::make_shared<ClusterOptions>();
  CLI::App* cluster = app.add_subcommand("cluster", "Run a sharded job on a cluster's scheduler (docs/CLUSTER.md)");
  cluster->require_subcommand(1);
  CLI::App* cmd = cluster->add_subcommand(
      "slurm", "Write the Slurm batch scripts of a sharded job (an array of shards, then merge and verify)");
  add_job_options(*cmd, opts->job, true);
  cmd->get_option("--threads")->description("CPUs of each shard's task, and its -j (default: 4)");
  cmd->add_option("--shards", opts->shards, "Shards of the job: one array task each")
      ->required()
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--partition", opts->partition, "Slurm partition (default: the cluster's)");
  cmd->add_option("--account", opts->account, "Slurm account (default: the user's)");
  cmd->add_option("--time", opts->time_minutes,
                  "Time limit of each task in minutes (default: three times the estimate, plus 5, at least 10)")
      ->check(CLI::Range(1, 525600));
  cmd->add_option("--mem", opts->memory_mb,
                  "Memory of each task in MB (default: the shard's estimated peak plus a quarter, plus 256)")
      ->check(CLI::Range(1, 1 << 30));
  cmd->add_option("--max-array-size", opts->max_array_size,
                  "Slurm's MaxArraySize, for the commands printed without --submit (--submit asks scontrol)")
      ->check(CLI::Range(2, 4000001))
      ->capture_default_str();
  cmd->add_flag("--submit", opts->submit, "Submit the arrays and the merge with sbatch and print their job ids");
  cmd->callback([cmd, opts] { run_cluster_slurm(*cmd, *opts); });
}

}  // namespace trivox::cli
