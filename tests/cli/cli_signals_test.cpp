// SIGTERM and SIGINT for the commands other than slice (docs/CLI.md, "Exit codes"): a
// scheduler's SIGTERM, or Ctrl-C, ends probe and validate cleanly with exit 130 and an
// "interrupted" message, never by the signal itself, and they write nothing.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

struct Ended {
  bool signalled = false;
  int exit_code = -1;
  std::string err;
};

// Runs trivox with `args`, its standard input a pipe held open (so that probe waits for input)
// and standard output discarded; sends `sig` after `delay`; waits for it to end.
Ended run_and_signal(const std::vector<std::string>& args, int sig, std::chrono::milliseconds delay) {
  ScratchDir dir;
  const fs::path err = dir.path() / "stderr.txt";
  int input[2];
  if (::pipe(input) != 0) return {};
  const pid_t child = start_cli(args, input[0], -1, err, input[1]);
  ::close(input[0]);
  std::this_thread::sleep_for(delay);
  ::kill(child, sig);
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(input[1]);
  Ended e;
  e.signalled = WIFSIGNALED(status);
  e.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  e.err = read_text(err);
  return e;
}

TEST(CliSignals, ProbeWaitingForInputEndsWithExit130OnSigtermAndSigint) {
  const std::string model = (examples_dir() / "models" / "twisted_column.itd").string();
  for (int sig : {SIGTERM, SIGINT}) {
    const Ended e = run_and_signal({"probe", model}, sig, std::chrono::milliseconds(1500));
    EXPECT_FALSE(e.signalled) << "killed by signal " << sig;
    EXPECT_EQ(e.exit_code, 130) << e.err;
    EXPECT_NE(e.err.find("trivox: interrupted: stopped by a signal while"), std::string::npos) << e.err;
  }
}

// validate with many sample layers runs for seconds: a signal at any moment after the program
// has started ends it with exit 130 (or it had finished, exit 0), never by the signal, and it
// leaves no output folder behind.
TEST(CliSignals, ValidateStopsCleanlyAtASignalWrittenNothing) {
  ScratchDir dir;
  const std::string scene = (examples_dir() / "scenes" / "quick_start.json").string();
  int interrupted = 0;
  for (int delay_ms : {400, 700, 1000}) {
    const fs::path out = dir.path() / ("out" + std::to_string(delay_ms));
    const Ended e = run_and_signal({"validate", scene, "-o", out.string(), "--samples", "50"}, SIGTERM,
                                   std::chrono::milliseconds(delay_ms));
    EXPECT_FALSE(e.signalled) << delay_ms << " ms";
    EXPECT_TRUE(e.exit_code == 130 || e.exit_code == 0) << e.exit_code << ": " << e.err;
    if (e.exit_code == 130) {
      ++interrupted;
      EXPECT_NE(e.err.find("trivox: interrupted: "), std::string::npos) << e.err;
    }
    EXPECT_FALSE(fs::exists(out)) << out;
  }
  EXPECT_GT(interrupted, 0) << "validate always finished before the signal: the test no longer tests anything";
}

}  // namespace
}  // namespace trivox::test
