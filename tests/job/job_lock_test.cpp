// The lock of a job's output folder (include/trivox/job/job_lock.h) in the library, as
// run_slice_job and the Python API take it; tests/cli/cli_folder_lock_test.cpp runs the
// program against it.
#include "trivox/job/job_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "trivox/error.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// The library's own lock (JobFolderLock), as the Python API and run_slice_job use it: locks
// conflict within one process too, and a whole job excludes shards and the other way round.
TEST(JobFolderLock, LocksConflictAsTheJobsWouldAndRemoveTheirFiles) {
  const fs::path out = fs::temp_directory_path() / fmt::format("trivox-job-lock-test-{}", ::getpid());
  fs::remove_all(out);
  {
    const JobFolderLock whole(out);
    EXPECT_TRUE(fs::exists(out / ".trivox.lock"));
    EXPECT_THROW(JobFolderLock{out}, Error);
    EXPECT_THROW((JobFolderLock{out, 1, 3}), Error);
    EXPECT_FALSE(whole.taken_over_from());
  }
  EXPECT_FALSE(fs::exists(out / ".trivox.lock"));
  {
    const JobFolderLock one(out, 1, 3), two(out, 2, 3);
    EXPECT_THROW((JobFolderLock{out, 2, 3}), Error);
    EXPECT_THROW(JobFolderLock{out}, Error);
  }
  EXPECT_TRUE(fs::is_empty(out));
  fs::remove_all(out);
}

// The reserve for a failure's manifest is real space in the job's own lock file, grown and
// given back, and the holder line stays readable in front of it.
TEST(JobFolderLock, TheReserveHoldsSpaceInTheJobsLockFileAndGivesItBack) {
  const fs::path out = fs::temp_directory_path() / fmt::format("trivox-job-lock-reserve-{}", ::getpid());
  fs::remove_all(out);
  for (const int shards : {1, 2}) {
    JobFolderLock lock(out, shards, shards);
    const fs::path file = out / (shards == 1 ? job_lock_file_name() : shard_lock_file_name(2));
    const std::uintmax_t line = fs::file_size(file);
    EXPECT_GT(line, 0u);
    JobFolderLock& l = lock;
    ASSERT_TRUE(l.reserve_bytes(100000));
    EXPECT_EQ(fs::file_size(file), line + 100000);
    ASSERT_TRUE(l.reserve_bytes(50000));  // never shrinks
    EXPECT_EQ(fs::file_size(file), line + 100000);
    std::ifstream in(file);
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first.rfind(fmt::format("pid={} host=", ::getpid()), 0), 0u) << first;
    l.release_reserve();
    EXPECT_EQ(fs::file_size(file), line);
  }
  EXPECT_TRUE(fs::is_empty(out));
  fs::remove_all(out);
}

// A requeued scheduler task runs as the same task; a lock a file server still holds for its
// lost predecessor (a process not running here) is taken over, and a lock of any other task,
// or of this task's process still running on this machine, refuses the job.
TEST(JobFolderLock, ALockStillHeldForThisTaskByAProcessNotRunningHereIsTakenOver) {
  const fs::path out = fs::temp_directory_path() / fmt::format("trivox-job-lock-task-{}", ::getpid());
  fs::remove_all(out);
  fs::create_directories(out);
  const fs::path shard_lock = out / shard_lock_file_name(1);
  // The lost node's lock: held by a process of this machine (the file server's view), its line
  // naming another host.
  const auto hold = [&](const std::string& line) {
    int ready[2];
    EXPECT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    if (child == 0) {
      const int fd = ::open(shard_lock.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
      ::flock(fd, LOCK_EX);
      (void)!::write(fd, line.data(), line.size());
      (void)!::write(ready[1], "x", 1);
      ::pause();
      ::_exit(0);
    }
    char c;
    EXPECT_EQ(::read(ready[0], &c, 1), 1);
    ::close(ready[0]);
    ::close(ready[1]);
    return child;
  };
  const auto stop = [](pid_t child) {
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
  };
  ::setenv("TRIVOX_TASK_ID", "test:7_1", 1);
  pid_t holder = hold("pid=4242 host=othernode task=test:7_1 started=2026-11-28T10:00:00Z\n");
  {
    const JobFolderLock lock(out, 1, 2);
    ASSERT_TRUE(lock.taken_over_from());
    EXPECT_NE(lock.taken_over_from()->find("host=othernode task=test:7_1"), std::string::npos);
    std::ifstream in(shard_lock);
    std::string line;
    std::getline(in, line);
    EXPECT_NE(line.find(fmt::format("pid={} host=", ::getpid())), std::string::npos) << line;
    EXPECT_NE(line.find(" task=test:7_1 "), std::string::npos) << line;
  }
  stop(holder);
  // Another task's lock, and this task's held by a live process of this machine, refuse it.
  holder = hold("pid=4242 host=othernode task=test:7_2 started=2026-11-28T10:00:00Z\n");
  try {
    const JobFolderLock lock(out, 1, 2);
    ADD_FAILURE() << "took over another task's lock";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("process 4242 on host othernode (task test:7_2)"), std::string::npos)
        << e.what();
  }
  stop(holder);
  holder = hold(fmt::format("pid={} host={} task=test:7_1 started=2026-11-28T10:00:00Z\n", ::getpid(), machine_name()));
  EXPECT_THROW((JobFolderLock{out, 1, 2}), Error);
  stop(holder);
  ::unsetenv("TRIVOX_TASK_ID");
  fs::remove_all(out);
}

// Without flock (TRIVOX_LOCKS=files, as where flock answers ENOLCK): the lock files alone
// refuse what the flocks refuse, a file whose holder has ended is taken over, and one of
// another machine is not, unless it is an earlier run of this very task.
TEST(JobFolderLock, WithoutFlockTheLockFilesRefuseWhatTheFlocksRefuse) {
  const fs::path out = fs::temp_directory_path() / fmt::format("trivox-job-lock-files-{}", ::getpid());
  fs::remove_all(out);
  ::setenv("TRIVOX_LOCKS", "files", 1);
  {
    const JobFolderLock whole(out);
    EXPECT_TRUE(whole.locked_by_files());
    EXPECT_THROW(JobFolderLock{out}, Error);
    EXPECT_THROW((JobFolderLock{out, 1, 3}), Error);
  }
  EXPECT_FALSE(fs::exists(out / ".trivox.lock"));
  {
    const JobFolderLock one(out, 1, 3), two(out, 2, 3);
    EXPECT_THROW((JobFolderLock{out, 2, 3}), Error);
    try {
      const JobFolderLock whole(out);
      ADD_FAILURE() << "a whole job beside running shards";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fmt::format("shard 1 (process {} on host {}", ::getpid(), machine_name())),
                std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(fs::exists(out / ".trivox.lock"));  // the refused job's file is gone again
  }
  EXPECT_TRUE(fs::is_empty(out));
  const auto write_line = [&](const std::string& name, const std::string& line) { std::ofstream(out / name) << line; };
  // A killed job's file: its process no longer runs here.
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  write_line(".trivox.lock", fmt::format("pid={} host={} started=2026-11-28T10:00:00Z\n", dead, machine_name()));
  {
    const JobFolderLock whole(out);
    ASSERT_TRUE(whole.taken_over_from());
    EXPECT_NE(whole.taken_over_from()->find(fmt::format("pid={} ", dead)), std::string::npos);
  }
  // A shard's file of another machine: it may run, so neither a whole job nor that shard starts.
  write_line(".trivox-shard-2.lock", "pid=4242 host=othernode task=test:9_2 started=2026-11-28T10:00:00Z\n");
  EXPECT_THROW(JobFolderLock{out}, Error);
  EXPECT_THROW((JobFolderLock{out, 2, 3}), Error);
  {
    const JobFolderLock other_shard(out, 3, 3);  // the other shards run beside it
  }
  // Unless this process runs as that task again (requeued after its node was lost).
  ::setenv("TRIVOX_TASK_ID", "test:9_2", 1);
  {
    const JobFolderLock shard(out, 2, 3);
    ASSERT_TRUE(shard.taken_over_from());
    EXPECT_NE(shard.taken_over_from()->find("host=othernode"), std::string::npos);
  }
  ::unsetenv("TRIVOX_TASK_ID");
  ::unsetenv("TRIVOX_LOCKS");
  EXPECT_TRUE(fs::is_empty(out));
  fs::remove_all(out);
}

// The task a lock line names: Slurm's array task, then within an srun step its process.
TEST(JobFolderLock, TheLockLineNamesSlurmsTaskAndProcess) {
  const fs::path out = fs::temp_directory_path() / fmt::format("trivox-job-lock-slurm-{}", ::getpid());
  fs::remove_all(out);
  const auto line_of = [&] {
    const JobFolderLock lock(out, 2, 4);
    std::ifstream in(out / shard_lock_file_name(2));
    std::string line;
    std::getline(in, line);
    return line;
  };
  const auto clear = [] {
    for (const char* name : {"SLURM_JOB_ID", "SLURM_ARRAY_JOB_ID", "SLURM_ARRAY_TASK_ID", "SLURM_STEP_ID",
                             "SLURM_PROCID", "TRIVOX_TASK_ID"})
      ::unsetenv(name);
  };
  clear();
  EXPECT_EQ(line_of().find(" task="), std::string::npos);  // no scheduler: no task
  ::setenv("SLURM_JOB_ID", "41", 1);
  ::setenv("SLURM_ARRAY_JOB_ID", "40", 1);
  ::setenv("SLURM_ARRAY_TASK_ID", "2", 1);
  EXPECT_NE(line_of().find(" task=slurm:40_2 started="), std::string::npos) << line_of();
  ::setenv("SLURM_STEP_ID", "0", 1);
  ::setenv("SLURM_PROCID", "3", 1);
  EXPECT_NE(line_of().find(" task=slurm:40_2.0.3 started="), std::string::npos) << line_of();
  ::setenv("TRIVOX_TASK_ID", "k8s:job-1", 1);
  EXPECT_NE(line_of().find(" task=k8s:job-1 started="), std::string::npos) << line_of();
  clear();
  fs::remove_all(out);
}

}  // namespace
}  // namespace trivox
