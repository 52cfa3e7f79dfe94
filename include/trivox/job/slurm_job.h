// A sharded job on a Slurm cluster (docs/CLUSTER.md): the batch scripts of an array with one
// task per shard (`trivox slice --shard I/N --resume`, requeued before its time limit) and of
// the merge that depends on it (`trivox merge` then `trivox verify`). The scripts are plain
// text for sbatch; nothing here talks to Slurm.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace trivox {

struct SlurmJobParams {
  std::filesystem::path program;        // the trivox program every node runs (absolute)
  std::filesystem::path scene;          // absolute: the tasks do not start in this folder
  std::filesystem::path output_dir;     // absolute, on a file system every node sees
  std::vector<std::string> slice_args;  // further `trivox slice` options, passed on word for word
  int shards = 1;
  int cpus_per_task = 1;           // also the shard's -j
  std::uint64_t memory_mb = 0;     // --mem of each task; 0: the partition's default
  int time_minutes = 0;            // --time of each task; 0: the partition's default
  std::string partition, account;  // empty: Slurm's defaults
  std::string job_name = "trivox";
  // Seconds before the time limit at which Slurm signals the task (--signal=B:USR1@N): the
  // shard stops after its layers in progress and the task requeues itself.
  int warning_seconds = 120;
  // The job writes stack outputs (gcvf, sl1s, tiff, vdb, previews): the shards keep their
  // layers as stack parts, and the merge task writes the outputs from them with the whole
  // job's `trivox slice --resume`, on cpus_per_task cores with merge_memory_mb (0: the
  // partition's default).
  bool stack_outputs = false;
  std::uint64_t merge_memory_mb = 0;
};

// One array of a job that has more shards than the cluster's MaxArraySize allows in one
// array: its tasks are shards offset + 1 .. offset + count (the array's indices 1 .. count).
struct SlurmArrayPart {
  int offset = 0, count = 0;
};
// The arrays that cover `shards` when an array index must stay below `max_array_size`
// (Slurm's MaxArraySize, 1001 by default): ceil(shards / (max_array_size - 1)) parts; throws
// Error when that is more than 1000.
std::vector<SlurmArrayPart> slurm_array_parts(int shards, int max_array_size);

// The shard task's batch script. Its first argument is the part's offset (0 for the first
// part): task i slices shard offset + i. It traps USR1 (the time-limit warning) and TERM (a
// preemption): the shard stops at a layer boundary, the task requeues itself with scontrol
// and exits 0; a rerun resumes the shard (--resume keeps its finished layers). Logs go to
// DIR/slurm/shard-<shard>.log, appended across reruns.
std::string slurm_shard_script(const SlurmJobParams& params);

// The merge task's batch script: `trivox merge DIR`, for a job with stack outputs the whole
// job's `trivox slice SCENE -o DIR --resume` that writes them, and `trivox verify DIR` (only
// the verify for one shard, which is the whole job);
// submitted with --dependency=afterok on every array part, so a shard that fails for good
// leaves it pending.
std::string slurm_merge_script(const SlurmJobParams& params);

// `word` quoted for bash when it holds anything but letters, digits and "-_./:=@%+,".
std::string shell_word(const std::string& word);

}  // namespace trivox
