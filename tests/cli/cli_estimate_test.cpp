// `validate` on the stack outputs (tiff, vdb, gcvf), which write nothing per layer: it counts
// their files, the disk their spools take while the job runs and the memory of the OpenVDB
// grids, and refuses a job with grids that a memory limit cannot take.
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

std::string scene() { return shell_quote(examples_dir() / "scenes" / "quick_start.json"); }
// 12 model layers padded to 30.
std::string job_args(const std::string& formats) { return scene() + " --layers 1:12 -j 2 --format " + formats; }

// The number before a unit in `text` after `key` ("about 1.2 MB" -> 1.2e6 bytes); -1 if absent.
double bytes_after(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return -1;
  std::size_t end = 0;
  const std::string rest = text.substr(at + key.size());
  const double value = std::stod(rest, &end);
  const std::string unit = rest.substr(end + 1, 2);
  return value * (unit == "GB" ? 1e9 : unit == "MB" ? 1e6 : unit == "kB" ? 1e3 : 1.0);
}

// The stack outputs' share of the peak memory: "(12.3 MB of it for the stack outputs)".
double stack_memory(const std::string& text) {
  const std::size_t at = text.find(" of it for the stack outputs");
  const std::size_t open = text.rfind('(', at);
  if (at == std::string::npos || open == std::string::npos) return -1;
  return bytes_after(text.substr(open, at - open), "(");
}

TEST(CliEstimate, ValidateCountsTheStackOutputs) {
  for (const std::string format : {"tiff", "vdb", "gcvf"}) {
    SCOPED_TRACE(format);
    const CliResult v = run_cli("validate " + job_args(format));
    ASSERT_EQ(v.exit_code, 0) << v.err;
    // materials.csv, the stack, stats.json and the manifest; no file per layer.
    EXPECT_NE(v.out.find("files (from 3 sample layers)"), std::string::npos) << v.out;
    EXPECT_NE(v.out.find(" in 4 files"), std::string::npos) << v.out;
    // The stack of 12 model layers of 710 x 355 px is tens of kB at least (the TIFF's pages
    // are the smallest: about 37 kB in all).
    EXPECT_GT(bytes_after(v.out, "output: about "), 30e3) << v.out;
    EXPECT_GT(bytes_after(v.out, "spool files: about "), 10e3) << v.out;
    if (format == "vdb") {
      EXPECT_GT(stack_memory(v.out), 1e6) << v.out;
    }
  }
}

// A memory limit between the plain job's peak and that with OpenVDB grids: the first runs,
// the second is refused, naming the grids' share.
TEST(CliEstimate, TheOpenVdbGridsCountAgainstTheMemoryLimit) {
  const CliResult plain = run_cli("validate " + job_args("voxelprint"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const CliResult vdb = run_cli("validate " + job_args("voxelprint,vdb"));
  ASSERT_EQ(vdb.exit_code, 0) << vdb.err;
  const double plain_peak = bytes_after(plain.out, "peak memory: about ");
  const double grids = stack_memory(vdb.out);
  ASSERT_GT(plain_peak, 0) << plain.out;
  ASSERT_GT(grids, 1e6) << vdb.out;
  const std::string limit = fmt::format(" --memory-limit {:.3f}", (plain_peak + grids / 2) / 1e6);
  const CliResult accepted = run_cli("validate " + job_args("voxelprint") + limit);
  EXPECT_EQ(accepted.exit_code, 0) << accepted.err;
  const CliResult refused = run_cli("validate " + job_args("voxelprint,vdb") + limit);
  EXPECT_EQ(refused.exit_code, 3) << refused.out;
  EXPECT_NE(refused.err.find("of it for the stack outputs"), std::string::npos) << refused.err;
}

}  // namespace
}  // namespace trivox::test
