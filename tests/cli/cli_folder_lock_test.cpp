// One job per output folder (docs/CLI.md, "One job per folder"): a job into a folder another
// job holds is refused at once (exit 3, naming the folder and the other process); a lock
// left by a killed job is taken over; the shards of one job run at once; the lock files are
// gone when a job ends; merge takes the lock, verify and validate do not. The other job is
// this test process, holding the lock through the library (JobFolderLock) as a running
// `trivox slice` does.
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"
#include "cli_small_scene.h"
#include "trivox/error.h"
#include "trivox/job/job_lock.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

class CliFolderLock : public ::testing::Test {
 protected:
  void SetUp() override { write_text(dir_.path() / "box.json", small_box_scene()); }
  CliResult slice(const std::string& options) {
    return run_cli(fmt::format("slice {} -o {} --layers 1:3 --min-layers 0 {}", shell_quote(dir_.path() / "box.json"),
                               shell_quote(out()), options));
  }
  fs::path out() const { return dir_.path() / "out"; }
  bool any_lock_file() const {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(out(), ec))
      if (entry.path().filename().string().ends_with(".lock")) return true;
    return false;
  }
  ScratchDir dir_;
};

TEST_F(CliFolderLock, ASecondJobIntoAHeldFolderIsRefusedAtOnceNamingTheFolderAndTheProcess) {
  std::optional<JobFolderLock> held(std::in_place, out());
  for (const char* options : {"-q", "-q --resume", "-q --format bitmaps,gcvf"}) {
    const auto start = std::chrono::steady_clock::now();
    const CliResult r = slice(options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.exit_code, 3) << options << ": " << r.err;
    EXPECT_NE(r.err.find(out().string() + ": another trivox job is writing into this folder"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(fmt::format("process {} on host", ::getpid())), std::string::npos) << r.err;
    EXPECT_LT(seconds, 5.0) << "refused only after " << seconds << " s";
  }
  EXPECT_FALSE(fs::exists(out() / "manifest.json"));  // nothing of the refused jobs
  held.reset();
  EXPECT_FALSE(fs::exists(out() / ".trivox.lock"));
  const CliResult r = slice("-q");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out() / "manifest.json"));
  EXPECT_FALSE(any_lock_file()) << "the job left its lock file";
  // --resume of the finished job takes the lock again and releases it.
  EXPECT_EQ(slice("-q --resume").exit_code, 0);
  EXPECT_FALSE(any_lock_file());
}

TEST_F(CliFolderLock, ALockLeftByAKilledJobIsTakenOver) {
  fs::create_directories(out());
  // What a killed job leaves: the file with its line, but no process holding the lock.
  write_text(out() / ".trivox.lock", "pid=999999 host=gone started=2026-01-01T00:00:00Z\n");
  const CliResult r = slice("");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("took over the lock of a job that ended without releasing it (pid=999999"), std::string::npos)
      << r.err;
  EXPECT_FALSE(any_lock_file());
  // A shard's lock too.
  fs::remove_all(out());
  fs::create_directories(out());
  write_text(out() / ".trivox-shard-2.lock", "pid=999999 host=gone started=2026-01-01T00:00:00Z\n");
  EXPECT_EQ(slice("-q --shard 2/2").exit_code, 0);
  EXPECT_FALSE(any_lock_file());
}

// Without flock (TRIVOX_LOCKS=files, as on a file system whose flock answers ENOLCK): the job
// says so, a second job is refused by the first's lock file, and a killed job's file, whose
// process no longer runs, is taken over.
TEST_F(CliFolderLock, WithoutFlockTheLockFilesLockTheFolderAndTheJobSaysSo) {
  ::setenv("TRIVOX_LOCKS", "files", 1);
  {
    std::optional<JobFolderLock> held(std::in_place, out());
    const CliResult refused = slice("-q");
    EXPECT_EQ(refused.exit_code, 3) << refused.err;
    EXPECT_NE(refused.err.find(fmt::format("process {} on host", ::getpid())), std::string::npos) << refused.err;
  }
  const CliResult r = slice("");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(fmt::format("note: {} is locked by its lock files alone", out().string())), std::string::npos)
      << r.err;
  EXPECT_FALSE(any_lock_file());
  const CliResult shard = slice("-q --shard 1/2");
  EXPECT_EQ(shard.exit_code, 0) << shard.err;
  EXPECT_FALSE(any_lock_file());
  ::unsetenv("TRIVOX_LOCKS");
}

TEST_F(CliFolderLock, TheShardsOfOneJobRunAtOnceButNotTwiceNorBesideAWholeJob) {
  std::optional<JobFolderLock> shard_one(std::in_place, out(), 1, 2);  // shard 1/2 running
  const CliResult two = slice("-q --shard 2/2");
  EXPECT_EQ(two.exit_code, 0) << two.err;
  // Resumed beside the running shard: its file in progress stays, one a killed job left goes.
  const fs::path in_progress = out() / fmt::format("slice_00001.png.tmp-{}-3", ::getpid());
  const fs::path left = out() / "slice_00003.png.tmp-999999-3";
  write_text(in_progress, "partial");
  write_text(left, "partial");
  const CliResult resumed = slice("-q --shard 2/2 --resume");
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_TRUE(fs::exists(in_progress)) << "a resumed shard removed another shard's file in progress";
  EXPECT_FALSE(fs::exists(left));
  fs::remove(in_progress);
  const CliResult one_again = slice("-q --shard 1/2");
  EXPECT_EQ(one_again.exit_code, 3) << one_again.err;
  EXPECT_NE(one_again.err.find(".trivox-shard-1.lock"), std::string::npos) << one_again.err;
  const CliResult whole = slice("-q");
  EXPECT_EQ(whole.exit_code, 3) << whole.err;
  EXPECT_NE(whole.err.find(fmt::format("shard 1 (process {} on host", ::getpid())), std::string::npos) << whole.err;
  shard_one.reset();
  EXPECT_EQ(slice("-q --shard 1/2").exit_code, 0);
  EXPECT_FALSE(any_lock_file());
  const CliResult merged = run_cli(fmt::format("merge {}", shell_quote(out())));
  EXPECT_EQ(merged.exit_code, 0) << merged.err;
}

// merge writes, so it holds the folder as a whole job does: refused while a shard runs.
// verify and validate only read the folder: they run beside a job and leave no lock file.
TEST_F(CliFolderLock, MergeWaitsForTheShardsWhileVerifyAndValidateTakeNoLock) {
  for (const char* shard : {"1/2", "2/2"}) ASSERT_EQ(slice(fmt::format("-q --shard {}", shard)).exit_code, 0);
  {
    const JobFolderLock running(out(), 2, 2);  // shard 2 running again (a --resume)
    const CliResult merge = run_cli("merge " + shell_quote(out()));
    EXPECT_EQ(merge.exit_code, 3) << merge.err;
    EXPECT_NE(merge.err.find(out().string() + ": another trivox job is writing into this folder"), std::string::npos)
        << merge.err;
    EXPECT_TRUE(fs::exists(out() / "manifest.shard-1-of-2.json"));
    EXPECT_FALSE(fs::exists(out() / "manifest.json"));
  }
  ASSERT_EQ(run_cli("merge " + shell_quote(out())).exit_code, 0);
  EXPECT_FALSE(any_lock_file()) << "merge left its lock file";
  const JobFolderLock running(out());
  const CliResult verify = run_cli("verify " + shell_quote(out()));
  EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
  const CliResult validate =
      run_cli(fmt::format("validate {} -o {} --samples 1", shell_quote(dir_.path() / "box.json"), shell_quote(out())));
  EXPECT_EQ(validate.exit_code, 0) << validate.out << validate.err;
}

// A folder slice cannot make is refused by validate too, with slice's message and exit code,
// and neither creates anything: a file where the folder should be, a folder under a file, a
// link to nothing.
TEST_F(CliFolderLock, ValidateRefusesTheOutputFoldersSliceRefusesWithTheSameMessage) {
  write_text(dir_.path() / "a.png", "not a folder");
  fs::create_symlink(dir_.path() / "gone", dir_.path() / "dangling");
  const fs::path file = dir_.path() / "a.png";
  for (const fs::path& folder : {file, file / "x", file / "x" / "y", dir_.path() / "dangling"}) {
    const std::string scene = shell_quote(dir_.path() / "box.json");
    const CliResult sliced = run_cli(fmt::format("slice {} -o {} --layers 1:3 -q", scene, shell_quote(folder)));
    const CliResult validated = run_cli(fmt::format("validate {} -o {} --samples 1", scene, shell_quote(folder)));
    EXPECT_EQ(sliced.exit_code, 4) << folder << sliced.err;
    EXPECT_EQ(validated.exit_code, 4) << folder << validated.out << validated.err;
    const std::string expected = "trivox: error: " + folder.string() + ": cannot create output folder: ";
    EXPECT_NE(sliced.err.find(expected), std::string::npos) << sliced.err;
    EXPECT_NE(validated.err.find(expected), std::string::npos) << validated.err;
    const auto last_line = [](const std::string& text) {
      const std::string trimmed = text.substr(0, text.find_last_not_of('\n') + 1);
      return trimmed.substr(trimmed.rfind('\n') + 1);
    };
    EXPECT_EQ(last_line(sliced.err), last_line(validated.err));
    EXPECT_EQ(validated.out.find("ok: the job can run"), std::string::npos) << validated.out;
  }
  EXPECT_FALSE(fs::exists(dir_.path() / "gone"));
  EXPECT_TRUE(fs::is_regular_file(file));
}

// validate's -o is checked, never created, and its help says so (slice's help says it is
// created, which slice does).
TEST_F(CliFolderLock, ValidateCreatesNoOutputFolderAndItsHelpSaysSo) {
  const fs::path folder = dir_.path() / "new" / "job";
  const CliResult validated =
      run_cli(fmt::format("validate {} -o {} --samples 1", shell_quote(dir_.path() / "box.json"), shell_quote(folder)));
  EXPECT_EQ(validated.exit_code, 0) << validated.err;
  EXPECT_FALSE(fs::exists(dir_.path() / "new"));
  const CliResult help = run_cli("validate --help");
  EXPECT_NE(help.out.find("nothing is created"), std::string::npos) << help.out;
  EXPECT_EQ(help.out.find("created if missing"), std::string::npos) << help.out;
  EXPECT_NE(run_cli("slice --help").out.find("created if missing"), std::string::npos);
}

}  // namespace
}  // namespace trivox::test
