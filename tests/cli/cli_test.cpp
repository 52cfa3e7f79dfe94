// The trivox program's contract with the shell: exit codes and error messages
// (docs/CLI.md, "Exit codes"). The program runs as a separate process on the bundled examples.
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "support/test_support.h"

namespace trivox::test {
namespace {

std::string column() { return shell_quote(examples_dir() / "models" / "twisted_column.itd"); }

TEST(CliUsage, HelpExitsZeroAndListsTheCommands) {
  const CliResult r = run_cli("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("info"), std::string::npos);
  EXPECT_NE(r.out.find("probe"), std::string::npos);
}

TEST(CliUsage, MissingSubcommandExits2) {
  const CliResult r = run_cli("");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(r.err.empty());
}

TEST(CliUsage, UnknownFlagExits2) {
  const CliResult r = run_cli("info --no-such-flag " + column());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliUsage, UnknownSubcommandExits2) { EXPECT_EQ(run_cli("frobnicate " + column()).exit_code, 2); }

TEST(CliUsage, MissingModelArgumentExits2) { EXPECT_EQ(run_cli("info").exit_code, 2); }

TEST(CliUsage, EvalWithoutPatchExits2) {
  const CliResult r = run_cli("probe --eval " + column(), "1 1 1\n");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--patch"), std::string::npos) << r.err;
}

TEST(CliUsage, PatchOutOfRangeExits2AndSaysHowManyPatches) {
  const CliResult r = run_cli("probe --patch 3 " + column(), "1 1 1\n");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("has 1 patch"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliUsage, NegativePatchExits2) { EXPECT_EQ(run_cli("probe --patch -1 " + column(), "1 1 1\n").exit_code, 2); }

TEST(CliErrors, MissingModelExits4AndNamesTheFile) {
  ScratchDir dir;
  const auto missing = dir.path() / "no_such_model.itd";
  const CliResult r = run_cli("info " + shell_quote(missing));
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("no_such_model.itd"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliErrors, MalformedModelExits3WithFileAndLine) {
  ScratchDir dir;
  const auto bad = dir.path() / "bad.itd";
  write_text(bad,
             "[OBJECT BAD\n"
             "    [TRIVAR BSPLINE 2 2 2 2 2 2 E3\n"
             "\t[KV 0 0 1 1]\n\t[KV 0 0 1 1]\n\t[KV 0 0 1 1]\n"
             "\t[0 0 0]\n"
             "\t[1 0 oops]\n");
  const CliResult r = run_cli("info " + shell_quote(bad));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("bad.itd:7:"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliErrors, UnknownFileTypeExits3) {
  ScratchDir dir;
  const auto model = dir.path() / "model.stl";
  write_text(model, "solid nothing\nendsolid nothing\n");
  const CliResult r = run_cli("info " + shell_quote(model));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("model.stl"), std::string::npos) << r.err;
}

TEST(CliErrors, UnwritableOutputExits4) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "skipped: this system has no /dev/full";
  const CliResult r = run_cli("info " + column(), {}, "/dev/full");
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.err.find("standard output"), std::string::npos) << r.err;
}

// Standard output whose reader has gone (`trivox info MODEL | head -c 0`): the program ends
// with exit 4 and says nothing, as a pipeline expects, instead of dying by SIGPIPE. The
// program runs with SIGPIPE at its default action, as from a shell.
TEST(CliErrors, AClosedPipeOnStandardOutputEndsQuietlyWithExit4) {
  ScratchDir dir;
  const std::filesystem::path err = dir.path() / "stderr.txt";
  const std::string model = (examples_dir() / "models" / "twisted_column.itd").string();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"info", model}, std::vector<std::string>{"--version"}}) {
    int ends[2];
    ASSERT_EQ(::pipe(ends), 0);
    ::close(ends[0]);  // no reader: every write fails with EPIPE (or raises SIGPIPE)
    const pid_t child = start_cli(args, -1, ends[1], err);
    ASSERT_GE(child, 0);
    ::close(ends[1]);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_FALSE(WIFSIGNALED(status)) << args[0] << ": killed by signal " << WTERMSIG(status);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 4) << args[0];
    EXPECT_EQ(read_text(err), "") << args[0];
  }
}

TEST(CliErrors, UnsupportedHierarchicalSplineExits3) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const CliResult r = run_cli("info " + shell_quote(dir / "volumes" / "gismo" / "thbcube.xml"));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("unsupported"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("thbcube.xml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace trivox::test
