// Long-job safety through the program, as a user or a scheduler drives it: SIGKILL and
// SIGINT at random moments followed by --resume, write errors injected with a file-size
// limit (RLIMIT_FSIZE, which needs no privileges), shards and merge, verify's exit code.
#include <filesystem>
#include <map>
#include <random>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/png_io.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

std::string scene() { return shell_quote(examples_dir() / "scenes" / "quick_start.json"); }
// 12 model layers padded to 30: about a second of work.
std::string slice_args(const fs::path& out) {
  return "slice " + scene() + " --layers 1:12 -q -j 2 -o " + shell_quote(out);
}

// No temporaries, and every PNG under a final name decodes.
void expect_no_partial_files(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    EXPECT_FALSE(is_atomic_temporary_name(e.path().filename().string())) << e.path();
    if (e.path().extension() == ".png") {
      EXPECT_NO_THROW(read_png_rgba(e.path())) << e.path();
    }
  }
}

class CliJob : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir;
    const CliResult r = run_cli(slice_args(reference()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    reference_ = new std::map<std::string, std::string>(folder_bytes(reference()));
  }
  static void TearDownTestSuite() {
    delete reference_;
    delete dir_;
  }
  static fs::path reference() { return dir_->path() / "reference"; }
  static ScratchDir* dir_;
  static std::map<std::string, std::string>* reference_;
};
ScratchDir* CliJob::dir_ = nullptr;
std::map<std::string, std::string>* CliJob::reference_ = nullptr;

TEST_F(CliJob, ReferenceHasAManifestAndVerifies) {
  EXPECT_EQ(reference_->count("manifest.json"), 1u);
  EXPECT_EQ(reference_->size(), 32u);  // 30 layers, materials.csv, manifest.json
  const CliResult r = run_cli("verify " + shell_quote(reference()));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("31 files"), std::string::npos) << r.out;
}

TEST_F(CliJob, KilledOrInterruptedAtRandomMomentsThenResumedIsByteIdentical) {
  std::mt19937 rng(4242);
  for (int trial = 0; trial < 4; ++trial) {
    ScratchDir dir;
    const fs::path out = dir.path() / "out";
    const bool gentle = trial % 2 == 1;  // SIGINT (Ctrl-C) or SIGKILL
    const double after_s = std::uniform_real_distribution<double>(0.05, 0.8)(rng);
    const CliResult killed =
        run_cli(fmt::format("--foreground --preserve-status -s {} {:.3f} {} {}", gentle ? "INT" : "KILL", after_s,
                            shell_quote(cli_path()), slice_args(out)),
                "", "", "timeout");
    // --foreground: timeout signals the program once. Without it, timeout also signals its
    // whole process group, so a second SIGINT could follow the first, and the program's
    // handler is reset after one Ctrl-C (a second one ends it at once, by design).
    // A signal that arrives before the program installed its handler (while it starts up)
    // ends it before any output exists; once a manifest exists, SIGINT must end cleanly.
    if (gentle && killed.exit_code != 0 && fs::exists(out / "manifest.json")) {
      EXPECT_EQ(killed.exit_code, 130) << killed.err;
      EXPECT_NE(killed.err.find("--resume"), std::string::npos) << killed.err;
      EXPECT_NE(read_text(out / "manifest.json").find("\"interrupted\""), std::string::npos);
    }
    if (fs::exists(out)) {
      if (gentle) expect_no_partial_files(out);
    }
    const CliResult resumed = run_cli(slice_args(out) + " --resume");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    expect_no_partial_files(out);
    EXPECT_EQ(folder_bytes(out), *reference_) << "trial " << trial << ", signal after " << after_s << " s";
  }
}

TEST_F(CliJob, WriteErrorNamesThePathLeavesNoBadFileAndResumeCompletes) {
  ScratchDir dir;
  const fs::path out = dir.path() / "out";
  // Files over 8 KiB fail with EFBIG: the model layers (about 10 KB) do, the empty padding
  // layers (about 5 KB) and the manifest do not. SIGXFSZ is ignored so that write() fails.
  // --no-checks: the up-front estimate would meet the limit first, in its scratch folder.
  const CliResult failed = run_cli(slice_args(out) + " --no-checks", "", "", "trap '' XFSZ; ulimit -f 16;");
  EXPECT_EQ(failed.exit_code, 4) << failed.err;
  EXPECT_NE(failed.err.find((out / "slice_000").string()), std::string::npos) << failed.err;
  EXPECT_NE(failed.err.find("File too large"), std::string::npos) << failed.err;
  expect_no_partial_files(out);
  EXPECT_NE(read_text(out / "manifest.json").find("\"failed\""), std::string::npos);
  // Whatever the manifest lists is intact.
  const CliResult partial = run_cli("verify " + shell_quote(out));
  EXPECT_EQ(partial.exit_code, 5);
  EXPECT_NE(partial.out.find("the job is failed"), std::string::npos) << partial.out;
  EXPECT_EQ(partial.out.find("SHA-256"), std::string::npos) << partial.out;

  const CliResult resumed = run_cli(slice_args(out) + " --resume");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("already complete"), std::string::npos) << resumed.out;
  EXPECT_EQ(folder_bytes(out), *reference_);
}

TEST_F(CliJob, ShardsMergedEqualOneRunAndVerifyCatchesCorruption) {
  ScratchDir dir;
  const fs::path out = dir.path() / "out";
  for (int i = 1; i <= 3; ++i) {
    const CliResult r = run_cli(slice_args(out) + fmt::format(" --shard {}/3", i));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const CliResult unmerged = run_cli("verify " + shell_quote(out));
  EXPECT_EQ(unmerged.exit_code, 4);
  EXPECT_NE(unmerged.err.find("trivox merge"), std::string::npos) << unmerged.err;
  const CliResult merged = run_cli("merge " + shell_quote(out));
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(folder_bytes(out), *reference_);

  std::string bytes = read_text(out / "slice_00007.png");
  bytes[bytes.size() - 20] = static_cast<char>(bytes[bytes.size() - 20] ^ 1);
  write_text(out / "slice_00007.png", bytes);
  const CliResult bad = run_cli("verify " + shell_quote(out));
  EXPECT_EQ(bad.exit_code, 5);
  EXPECT_NE(bad.out.find("slice_00007.png"), std::string::npos) << bad.out;
}

TEST_F(CliJob, ResumeOfAnotherJobIsRefusedWithTheDifference) {
  ScratchDir dir;
  const fs::path out = dir.path() / "out";
  fs::copy(reference(), out, fs::copy_options::recursive);
  const CliResult r = run_cli(slice_args(out) + " --resume --background 255,255,255");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("background_rgba"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
}

TEST_F(CliJob, BadShardIsAUsageError) {
  ScratchDir dir;
  for (const char* shard : {"0/3", "4/3", "1/0", "a/b", "2", "1/3x"}) {
    const CliResult r = run_cli(slice_args(dir.path() / "out") + " --shard " + shard);
    EXPECT_EQ(r.exit_code, 2) << shard;
    EXPECT_NE(r.err.find("--shard"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace trivox::test

namespace trivox::test {
namespace {

TEST(CliEstimate, ValidateAndInfoPrintTheEstimate) {
  ScratchDir dir;
  const CliResult v = run_cli("validate " + scene() + " --layers 1:12 -o " + shell_quote(dir.path() / "out"));
  EXPECT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("layers: 30 (12 of the model, 18 empty padding layers)"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("output: about"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("peak memory"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("ok: the job can run"), std::string::npos) << v.out;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));  // validate writes nothing
  const CliResult i = run_cli("info " + scene());
  EXPECT_EQ(i.exit_code, 0) << i.err;
  EXPECT_NE(i.out.find("time: about"), std::string::npos) << i.out;
}

TEST(CliEstimate, AJobOverTheMemoryLimitIsRefusedUpFrontUnlessOverridden) {
  ScratchDir dir;
  const auto out = dir.path() / "out";
  const CliResult v = run_cli("validate " + scene() + " --memory-limit 1");
  EXPECT_EQ(v.exit_code, 3);
  EXPECT_NE(v.err.find("memory"), std::string::npos) << v.err;
  const CliResult s = run_cli(slice_args(out) + " --memory-limit 1");
  EXPECT_EQ(s.exit_code, 3);
  EXPECT_NE(s.err.find("--no-checks"), std::string::npos) << s.err;
  EXPECT_FALSE(std::filesystem::exists(out));  // refused before anything was written
  const CliResult forced = run_cli(slice_args(out) + " --memory-limit 1 --no-checks");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

}  // namespace
}  // namespace trivox::test
