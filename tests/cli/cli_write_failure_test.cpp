// A job that fails to write records the failure in manifest.json (docs/CLI.md, "slice"):
// status "failed" with the message, whichever step failed - the colour-to-material sheet
// written before the first layer, or stats.json after the last - and even with --no-checks.
// The failures are provoked without a full disk: a folder stands where the file must go, so
// its rename fails. (A layer file or a stack file that cannot be written is
// tests/cli/cli_job_test.cpp's and cli_stack_job_test.cpp's case.)
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "cli_small_scene.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

TEST(CliWriteFailure, EveryStepThatFailsToWriteMarksTheManifestFailedWithTheMessage) {
  for (const char* blocked : {"materials.csv", "stats.json"}) {
    for (const char* checks : {"", "--no-checks"}) {
      SCOPED_TRACE(fmt::format("{} {}", blocked, checks));
      ScratchDir dir;
      write_text(dir.path() / "box.json", small_box_scene());
      const fs::path out = dir.path() / "out";
      fs::create_directories(out / blocked);
      const CliResult r = run_cli(fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q {}",
                                              shell_quote(dir.path() / "box.json"), shell_quote(out), checks));
      EXPECT_EQ(r.exit_code, 4) << r.err;
      EXPECT_NE(r.err.find((out / blocked).string() + ": cannot rename"), std::string::npos) << r.err;
      const nlohmann::json m = nlohmann::json::parse(read_text(out / "manifest.json"));
      EXPECT_EQ(m.at("status"), "failed");
      EXPECT_NE(m.at("message").get<std::string>().find((out / blocked).string() + ": cannot rename"),
                std::string::npos)
          << m.at("message");
      EXPECT_FALSE(fs::exists(out / ".trivox.lock"));
      // Once the way is clear, --resume completes the job.
      fs::remove(out / blocked);
      const CliResult resumed = run_cli(fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q --resume",
                                                    shell_quote(dir.path() / "box.json"), shell_quote(out)));
      EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
      EXPECT_EQ(nlohmann::json::parse(read_text(out / "manifest.json")).at("status"), "complete");
      EXPECT_EQ(run_cli("verify " + shell_quote(out)).exit_code, 0);
    }
  }
}

}  // namespace
}  // namespace trivox::test
