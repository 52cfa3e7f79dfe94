// The lock of a job's output folder (include/trivox/slice/job_lock.h) in the library, as
// run_slice_job and the Python API take it; tests/cli/cli_folder_lock_test.cpp runs the
// program against it.
#include "trivox/slice/job_lock.h"

#include <unistd.h>

#include <filesystem>

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

}  // namespace
}  // namespace trivox
