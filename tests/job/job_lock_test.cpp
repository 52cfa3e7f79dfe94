// The lock of a job's output folder (include/trivox/job/job_lock.h) in the library, as
// run_slice_job and the Python API take it; tests/cli/cli_folder_lock_test.cpp runs the
// program against it.
#include "trivox/job/job_lock.h"

#include <unistd.h>

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

}  // namespace
}  // namespace trivox
