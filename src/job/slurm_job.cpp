#include "trivox/job/slurm_job.h"

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/version.h"

namespace trivox {

std::string shell_word(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           std::string_view("-_./:=@%+,").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::vector<SlurmArrayPart> slurm_array_parts(int shards, int max_array_size) {
  if (shards < 1) throw Error(fmt::format("a cluster job needs at least 1 shard, not {}", shards));
  if (max_array_size < 2) throw Error(fmt::format("MaxArraySize {} leaves no array index", max_array_size));
  std::vector<SlurmArrayPart> parts;
  const int per_part = max_array_size - 1;  // indices 1 .. MaxArraySize - 1
  // Each part is a submission (and a line to print): a thousand is far beyond any real job.
  if (const int arrays = (shards + per_part - 1) / per_part; arrays > 1000)
    throw Error(fmt::format("{} shards at MaxArraySize {} need {} arrays; at most 1000 are submitted", shards,
                            max_array_size, arrays));
  for (int offset = 0; offset < shards; offset += per_part)
    parts.push_back({offset, std::min(per_part, shards - offset)});
  return parts;
}

namespace {

// The #SBATCH lines both scripts share.
std::string common_directives(const SlurmJobParams& p, const std::string& name) {
  std::string s = fmt::format("#SBATCH --job-name={}\n", shell_word(name));
  if (!p.partition.empty()) s += fmt::format("#SBATCH --partition={}\n", shell_word(p.partition));
  if (!p.account.empty()) s += fmt::format("#SBATCH --account={}\n", shell_word(p.account));
  return s;
}

std::string header(const SlurmJobParams& p, const char* what) {
  return fmt::format(
      "#!/bin/bash\n"
      "# {} of a trivox job on Slurm (docs/CLUSTER.md), written by `trivox cluster slurm` {}.\n"
      "# Scene {}, {} shards into {}.\n",
      what, version(), p.scene.string(), p.shards, p.output_dir.string());
}

// The `trivox slice` line of a task: the scene into the folder, `mode` (the shard and
// --resume), -j from the task's cores, then the job's options word for word.
std::string slice_command(const SlurmJobParams& p, const std::string& mode) {
  std::string s =
      fmt::format("{} slice {} -o {} {} -j \"${{SLURM_CPUS_PER_TASK:-{}}}\"", shell_word(p.program.string()),
                  shell_word(p.scene.string()), shell_word(p.output_dir.string()), mode, p.cpus_per_task);
  for (const std::string& a : p.slice_args) s += fmt::format(" {}", shell_word(a));
  return s;
}

}  // namespace

std::string slurm_shard_script(const SlurmJobParams& p) {
  const std::string dir = shell_word(p.output_dir.string());
  std::string s = header(p, "The shard tasks");
  s += "# Submit as an array, its first argument the offset of its shards:\n";
  s += fmt::format("#   sbatch --array=1-{} {} 0\n", std::min(p.shards, 1000),
                   shell_word((p.output_dir / "slurm" / "shards.sbatch").string()));
  s += common_directives(p, p.job_name);
  s += fmt::format("#SBATCH --cpus-per-task={}\n", p.cpus_per_task);
  if (p.memory_mb > 0) s += fmt::format("#SBATCH --mem={}M\n", p.memory_mb);
  if (p.time_minutes > 0) s += fmt::format("#SBATCH --time={}\n", p.time_minutes);
  s += "#SBATCH --requeue\n";
  s += fmt::format("#SBATCH --signal=B:USR1@{}\n", p.warning_seconds);
  s += "#SBATCH --open-mode=append\n";
  s += fmt::format("#SBATCH --output={}/slurm/slurm-%A_%a.out\n", dir);
  s += "set -u\n";
  s += "offset=${1:-0}\n";
  s += "shard=$((offset + SLURM_ARRAY_TASK_ID))\n";
  s += fmt::format("exec >>{}/slurm/shard-\"$shard\".log 2>&1\n", dir);
  s += "echo \"trivox: shard $shard of " + std::to_string(p.shards) +
       ": task ${SLURM_ARRAY_JOB_ID:-}_${SLURM_ARRAY_TASK_ID} on $(hostname), restart ${SLURM_RESTART_COUNT:-0}, "
       "$(date -u +%Y-%m-%dT%H:%M:%SZ)\"\n";
  s += "# The time-limit warning (USR1): the shard is stopped after the layers in progress (TERM,\n";
  s += "# which trivox takes as Ctrl-C; a background command of a script ignores INT), the task asks\n";
  s += "# to run again, and the rerun resumes the shard. TERM to the script (scancel, or a preemption,\n";
  s += "# which Slurm requeues itself) stops the shard the same way, without a requeue.\n";
  s += "stop_shard() {\n";
  s += "  kill -TERM \"$pid\" 2>/dev/null\n";
  s += "  wait \"$pid\"\n";
  s += "}\n";
  s += "stop_and_requeue() {\n";
  s += "  stop_shard\n";
  s += "  echo \"trivox: shard $shard stopped before the time limit; requeueing\"\n";
  s += "  scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  s += "  exit 0\n";
  s += "}\n";
  s += "trap stop_and_requeue USR1\n";
  s += "trap 'stop_shard; exit 143' TERM\n";
  s += slice_command(p, fmt::format("--shard \"$shard/{}\" --resume", p.shards)) + " &\n";
  s += "pid=$!\n";
  s += "wait \"$pid\"\n";
  s += "status=$?\n";
  s += "echo \"trivox: shard $shard exited with status $status\"\n";
  s += "exit \"$status\"\n";
  return s;
}

std::string slurm_merge_script(const SlurmJobParams& p) {
  const std::string dir = shell_word(p.output_dir.string()), program = shell_word(p.program.string());
  std::string s = header(p, "The merge");
  s += "# Submit with --dependency=afterok:<each shard array's job id>.\n";
  s += common_directives(p, p.job_name + "-merge");
  s += fmt::format("#SBATCH --cpus-per-task={}\n", p.stack_outputs ? p.cpus_per_task : 1);
  if (p.stack_outputs && p.merge_memory_mb > 0) s += fmt::format("#SBATCH --mem={}M\n", p.merge_memory_mb);
  if (p.time_minutes > 0) s += fmt::format("#SBATCH --time={}\n", p.time_minutes);
  s += fmt::format("#SBATCH --output={}/slurm/merge-%j.log\n", dir);
  s += "set -eu\n";
  if (p.shards == 1) {
    // Shard 1 of 1 is the whole job: it wrote manifest.json and its stack outputs itself.
    s += fmt::format("{} verify {}\n", program, dir);
    return s;
  }
  s += fmt::format("{} merge {}\n", program, dir);
  if (p.stack_outputs) {
    s += "# The stack outputs, from the layers the shards kept (their stack parts, removed after).\n";
    s += slice_command(p, "--resume") + "\n";
  }
  s += fmt::format("{} verify {}\n", program, dir);
  return s;
}

}  // namespace trivox
