// The construction cache through the program (docs/SLICING.md, "The construction cache"):
// `trivox slice` keeps constructed volumes in the output folder's .trivox-cache, and a repeated
// run, --resume and a second shard take them from there, with the same bytes as a run that
// built them; --no-cache neither reads nor writes it; a damaged entry is a warning and is built
// again; a job refused before it starts leaves no cache behind in a folder it created.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/io/model.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

class CliConstructionCache : public ::testing::Test {
 protected:
  void SetUp() override {
    write_text(dir_.path() / "tube.json", kRevolvedTubeScene);
    write_tube_profile(dir_.path() / "profile.itd", 8);
  }
  std::string slice(const fs::path& out, const std::string& extra = {}) const {
    return fmt::format("slice {} -o {} --layers 1:4 --min-layers 0 -j 2 {}", shell_quote(dir_.path() / "tube.json"),
                       shell_quote(out), extra);
  }
  // The job's files, without its statistics and the cache.
  static std::map<std::string, std::string> job_files(const fs::path& out) {
    std::map<std::string, std::string> files = folder_bytes(out);
    std::erase_if(files, [](const auto& f) { return f.first.starts_with(".trivox-cache/"); });
    return files;
  }
  static std::vector<fs::path> cache_entries(const fs::path& out) {
    std::vector<fs::path> entries;
    if (fs::exists(out / ".trivox-cache"))
      for (const auto& e : fs::directory_iterator(out / ".trivox-cache")) entries.push_back(e.path());
    return entries;
  }
  ScratchDir dir_;
};

constexpr const char* kTaken = "1 constructed volume taken from the construction cache";

TEST_F(CliConstructionCache, ARepeatedRunTakesTheVolumeAndWritesTheSameBytes) {
  const fs::path out = dir_.path() / "out";
  const CliResult first = run_cli(slice(out));
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_EQ(first.err.find("construction cache"), std::string::npos) << first.err;
  ASSERT_EQ(cache_entries(out).size(), 1u);
  const auto reference = job_files(out);
  EXPECT_EQ(reference.count("manifest.json"), 1u);
  const CliResult again = run_cli(slice(out));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.err.find(kTaken), std::string::npos) << again.err;
  EXPECT_EQ(job_files(out), reference);
  // -q keeps the note to itself.
  const CliResult quiet = run_cli(slice(out, "-q"));
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("construction cache"), std::string::npos) << quiet.err;
  // --no-cache builds the volume and leaves no cache.
  const fs::path plain = dir_.path() / "plain";
  const CliResult nocache = run_cli(slice(plain, "--no-cache"));
  ASSERT_EQ(nocache.exit_code, 0) << nocache.err;
  EXPECT_FALSE(fs::exists(plain / ".trivox-cache"));
  EXPECT_EQ(job_files(plain), reference);
}

TEST_F(CliConstructionCache, ResumeAndASecondShardTakeTheVolume) {
  const fs::path whole = dir_.path() / "whole";
  ASSERT_EQ(run_cli(slice(whole)).exit_code, 0);
  const CliResult resumed = run_cli(slice(whole, "--resume"));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find(kTaken), std::string::npos) << resumed.err;
  EXPECT_NE(resumed.out.find("already complete"), std::string::npos) << resumed.out;

  const fs::path shards = dir_.path() / "shards";
  const CliResult one = run_cli(slice(shards, "--shard 1/2"));
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(one.err.find("construction cache"), std::string::npos) << one.err;
  const CliResult two = run_cli(slice(shards, "--shard 2/2"));
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_NE(two.err.find(kTaken), std::string::npos) << two.err;
  ASSERT_EQ(run_cli("merge " + shell_quote(shards)).exit_code, 0);
  EXPECT_EQ(job_files(shards), job_files(whole));
}

TEST_F(CliConstructionCache, ADamagedEntryIsAWarningAndIsBuiltAgain) {
  const fs::path out = dir_.path() / "out";
  ASSERT_EQ(run_cli(slice(out)).exit_code, 0);
  const auto reference = job_files(out);
  const std::vector<fs::path> entries = cache_entries(out);
  ASSERT_EQ(entries.size(), 1u);
  write_text(entries[0], read_text(entries[0]).substr(0, 300));
  const CliResult damaged = run_cli(slice(out, "-q"));
  ASSERT_EQ(damaged.exit_code, 0) << damaged.err;
  EXPECT_NE(damaged.err.find("trivox: warning: construction cache: " + entries[0].string() + " is damaged"),
            std::string::npos)
      << damaged.err;
  EXPECT_EQ(job_files(out), reference);
  const CliResult mended = run_cli(slice(out));
  ASSERT_EQ(mended.exit_code, 0) << mended.err;
  EXPECT_NE(mended.err.find(kTaken), std::string::npos) << mended.err;
  EXPECT_EQ(mended.err.find("warning: construction cache"), std::string::npos) << mended.err;
}

TEST_F(CliConstructionCache, AChangedModelFileIsBuiltAgain) {
  const fs::path out = dir_.path() / "out";
  ASSERT_EQ(run_cli(slice(out)).exit_code, 0);
  write_tube_profile(dir_.path() / "profile.itd", 7);
  const CliResult changed = run_cli(slice(out));
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_EQ(changed.err.find("construction cache"), std::string::npos) << changed.err;
  EXPECT_EQ(cache_entries(out).size(), 2u);
  const fs::path plain = dir_.path() / "plain";
  ASSERT_EQ(run_cli(slice(plain, "--no-cache")).exit_code, 0);
  EXPECT_EQ(job_files(out), job_files(plain));
}

TEST_F(CliConstructionCache, AJobRefusedBeforeItStartsLeavesNoFolderBehind) {
  const fs::path out = dir_.path() / "new";
  const CliResult refused = run_cli(slice(out, "--memory-limit 1"));
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.err.find("memory"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace trivox::test
