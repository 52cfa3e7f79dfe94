// One job per output folder (docs/CLI.md, "One job per folder"): an advisory lock file in
// the folder, held while a job writes into it, so that a second job started into the same
// folder is refused at once instead of mixing its files and its manifest with the first's.
//
// A whole job holds `.trivox.lock` exclusively. Shard I of a split job holds `.trivox.lock`
// shared and `.trivox-shard-I.lock` exclusively, so that the shards of one job run at once
// while a whole job, or a second copy of the same shard, is refused. The locks are flock(2)
// locks: the kernel drops them when their process ends, however it ends, so a lock file
// left behind by a killed job holds nothing and the next job takes it over. The file holds
// one line naming its holder, `pid=<pid> host=<host> [task=<task>] started=<UTC time>`, for
// the message that refuses another job; it is removed when the job ends. The task is the
// scheduler's (TRIVOX_TASK_ID, else Slurm's array task `slurm:<job>_<index>` or job
// `slurm:<job>`, followed by `.<step>.<process>` inside an srun step): a lock still held for a run of this very task
// that is not running here (its node lost; a file server may keep such a lock for minutes) is taken over, since a
// scheduler runs one copy of a task at a time. While the job runs, its lock file also holds a reserve of disk space for
// the manifest of a failure (reserve_bytes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "trivox/output/atomic_file.h"

namespace trivox {

class JobFolderLock {
 public:
  // Creates `dir` when it is missing and takes the job's locks in it, without waiting.
  // Throws Error (an input error: the folder is taken) naming the folder and the process
  // that holds it when another job holds a lock this one needs; IoError when the folder or
  // the lock file cannot be created.
  JobFolderLock(const std::filesystem::path& dir, int shard_index = 1, int shard_count = 1);
  ~JobFolderLock();  // releases the locks and removes the lock files no other job holds
  JobFolderLock(const JobFolderLock&) = delete;
  JobFolderLock& operator=(const JobFolderLock&) = delete;

  const std::filesystem::path& dir() const noexcept;
  int shard_index() const noexcept;
  int shard_count() const noexcept;
  // The holder line of a lock file this job took over from a job that ended without removing
  // it (killed, or a power cut); nullopt when the lock files were absent or empty.
  const std::optional<std::string>& taken_over_from() const noexcept;
  // True when the folder's file system has no flock locks (flock answers ENOLCK, EOPNOTSUPP
  // or ENOSYS) or TRIVOX_LOCKS=files asks for it: the lock files alone lock the folder. Each
  // is created with O_EXCL and held while it exists with the line of a job that runs: one of
  // this machine whose process runs, one of another machine (which cannot be judged from
  // here), or a run of this task (above) on no machine it can see. A whole job holds
  // .trivox.lock and refuses to start beside the shards' files; a shard holds its own and
  // refuses to start beside a whole job's. A file whose holder has ended is taken over. Two
  // jobs that start in the same instant into one folder are told apart by O_EXCL; a lock
  // file of a lost machine stays until removed by hand (docs/CLUSTER.md, "Locks").
  bool locked_by_files() const noexcept;

  // Whose temporaries (output/atomic_file.h) a job holding this lock may judge stale: every
  // machine's for a whole job, which holds the folder alone; this machine's for a shard, which
  // cannot see the processes of the other shards' machines.
  StaleTemporaries stale_temporaries() const noexcept;

  // Disk space held for the manifest that records a failure: a full disk would leave no room
  // to write it. The job's own lock file (the shard's for a shard) is extended to hold
  // `bytes` more than its line, never shrinking; false when the file system has no room (the
  // job goes on without it). release_reserve() gives the space back, for that last write.
  bool reserve_bytes(std::uint64_t bytes);
  void release_reserve() noexcept;

 private:
  struct Held;  // the folder, the shard, the lock files' descriptors, the disk reserve
  std::unique_ptr<Held> held_;
};

// Why `dir` cannot be made a job's output folder, found without creating or writing anything:
// "DIR: cannot create output folder: REASON", the message JobFolderLock throws (as IoError)
// before it creates the folder, so that `trivox validate` refuses what `trivox slice` refuses.
// nullopt when `dir` is a folder, or the nearest part of it that exists is a folder this
// process may create entries in.
std::optional<std::string> output_folder_problem(const std::filesystem::path& dir);

// The lock files' names: ".trivox.lock", and ".trivox-shard-I.lock" for shard I.
std::string job_lock_file_name();
std::string shard_lock_file_name(int shard_index);

}  // namespace trivox
