// A write that fails in a stack output's final write (injected with a file-size limit,
// RLIMIT_FSIZE, as for the layer files in cli_job_test.cpp): the error names the file, no
// corrupt, temporary or spool file is left, the manifest says the job failed with every
// layer intact, and `--resume` completes with the bytes of an uninterrupted run.
#include <filesystem>
#include <map>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/output/atomic_file.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

std::string scene() { return shell_quote(examples_dir() / "scenes" / "quick_start.json"); }
// 12 model layers padded to 30.
std::string job_args(const std::string& formats) { return scene() + " --layers 1:12 -j 2 --format " + formats; }

// No temporary and no spool file; the stack, if present, is whole (it is not: it failed).
void expect_no_partial_stack(const fs::path& out, const std::string& stack) {
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    if (!e.is_regular_file()) continue;
    EXPECT_FALSE(is_atomic_temporary_name(e.path().filename().string())) << e.path();
    EXPECT_NE(e.path().extension(), ".spool") << e.path();
  }
  EXPECT_FALSE(fs::exists(out / stack)) << stack;
}

// Layer images of about 10 kB, the manifest and the stack's spool fit under the limit; the
// final stack file does not (a 90 kB TIFF of 37 kB of pages, an 850 kB OpenVDB file of a
// spool of about 120 kB).
TEST(CliStackJob, AWriteErrorInTheStackNamesTheFileLeavesNoBadFileAndResumeCompletes) {
  const struct {
    std::string format, stack;
    int limit_blocks;  // of 512 bytes (ulimit -f)
  } cases[] = {{"tiff", "tiff/stack.tif", 128}, {"vdb", "vdb/stack.vdb", 800}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.format);
    ScratchDir dir;
    const std::string args = job_args("voxelprint," + c.format) + " -q -o ";
    const CliResult ref = run_cli("slice " + args + shell_quote(dir.path() / "reference"));
    ASSERT_EQ(ref.exit_code, 0) << ref.err;
    ASSERT_GT(fs::file_size(dir.path() / "reference" / c.stack), static_cast<std::uintmax_t>(c.limit_blocks) * 512u);

    const fs::path out = dir.path() / "out";
    // --no-checks: the up-front estimate would meet the limit first, in its scratch folder.
    const CliResult failed = run_cli("slice " + args + shell_quote(out) + " --no-checks", "", "",
                                     fmt::format("trap '' XFSZ; ulimit -f {};", c.limit_blocks));
    EXPECT_EQ(failed.exit_code, 4) << failed.err;
    EXPECT_NE(failed.err.find((out / c.stack).string()), std::string::npos) << failed.err;
    EXPECT_NE(failed.err.find("File too large"), std::string::npos) << failed.err;
    expect_no_partial_stack(out, c.stack);
    EXPECT_NE(read_text(out / "manifest.json").find("\"failed\""), std::string::npos);
    // Every layer is complete and listed; only the stack is missing.
    const CliResult partial = run_cli("verify " + shell_quote(out));
    EXPECT_EQ(partial.exit_code, 5);
    EXPECT_NE(partial.out.find("the job is failed"), std::string::npos) << partial.out;
    EXPECT_EQ(partial.out.find("SHA-256"), std::string::npos) << partial.out;
    EXPECT_EQ(partial.out.find("has no files"), std::string::npos) << partial.out;

    const CliResult resumed = run_cli("slice " + args + shell_quote(out) + " --resume");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    EXPECT_NE(resumed.out.find("resumed: 30 layers were already complete"), std::string::npos) << resumed.out;
    EXPECT_EQ(folder_bytes(out), folder_bytes(dir.path() / "reference"));
    EXPECT_EQ(run_cli("verify " + shell_quote(out)).exit_code, 0);
  }
}

}  // namespace
}  // namespace trivox::test
