// Names are not paths (docs/CLI.md, "Names in file names"): the prefix and every material
// name that becomes part of a file name is refused, with exit 3 naming the option or the
// scene field, when it holds a folder separator, "..", a control character or more than 100
// bytes; nothing is written outside -o; and a failure in the estimate's scratch folder is
// reported with the output folder's path, never the scratch folder's internal name.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"
#include "cli_small_scene.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// Every path under `dir`, relative to it.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) names.push_back(fs::relative(entry, dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(CliNames, APrefixThatIsAPathIsRefusedAndNothingIsWritten) {
  const std::string long_prefix(101, 'p');
  const struct {
    std::string prefix, reason;
  } cases[] = {
      {"../evil_", "it holds '/', a folder separator"},
      {"a/b_", "it holds '/', a folder separator"},
      {"a\\b_", "it holds '\\', a folder separator on Windows"},
      {"..evil_", "it holds \"..\", the parent folder"},
      {"a\tb", "it holds the control character 0x09"},
      {long_prefix, "it is 101 bytes long, and at most 100 go into a file name"},
  };
  for (const auto& c : cases) {
    ScratchDir dir;
    write_text(dir.path() / "box.json", small_box_scene());
    for (const char* command : {"slice -q", "validate"}) {
      const CliResult r = run_cli(fmt::format(
          "{} {} -o {} --layers 1:1 --min-layers 0 --format voxelprint,gcvf "
          "--prefix {}",
          command, shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out"), shell_quote(c.prefix)));
      EXPECT_EQ(r.exit_code, 3) << command << " --prefix " << c.prefix << ": " << r.err;
      EXPECT_NE(r.err.find("trivox: error: --prefix '"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(c.reason), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find("trivox-estimate"), std::string::npos) << r.err;
      // The scene alone: no output folder, nothing beside it.
      EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"box.json"}) << command << " --prefix " << c.prefix;
    }
  }
  // The 100-byte prefix is the longest taken.
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene());
  const CliResult r = run_cli(fmt::format("slice {} -o {} --layers 1:1 --min-layers 0 -q --prefix {}",
                                          shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out"),
                                          std::string(100, 'p')));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.path() / "out" / (std::string(100, 'p') + "00001.png")));
}

TEST(CliNames, AMaterialNamedWithASlashIsRefusedForTheFormatsThatNameFilesByMaterial) {
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene({"a/b"}));
  for (const char* format : {"bitmaps", "legacy"}) {
    for (const char* checks : {"", "--no-checks"}) {
      const CliResult r =
          run_cli(fmt::format("slice {} -o {} --layers 1:1 --min-layers 0 -q --format {} {}",
                              shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out"), format, checks));
      EXPECT_EQ(r.exit_code, 3) << format << ": " << r.err;
      EXPECT_NE(r.err.find(fmt::format("box.json: /materials/0/name: the material 'a/b' names the files of output "
                                       "'{}', so it cannot be part of a file name: it holds '/'",
                                       format)),
                std::string::npos)
          << r.err;
      EXPECT_EQ(r.err.find("trivox-estimate"), std::string::npos) << r.err;
      EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"box.json"}) << format << " " << checks;
    }
  }
  // Voxel Print images are named by layer only: the name is no obstacle there.
  const CliResult r = run_cli(fmt::format("slice {} -o {} --layers 1:1 --min-layers 0 -q",
                                          shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A write that fails in the estimate's scratch folder (a file-size limit here, a full
// temporary directory elsewhere) names the output file the sample stands for and the
// temporary directory, not the scratch folder.
TEST(CliNames, AFailureInTheEstimatesScratchFolderNamesTheOutputFolder) {
  ScratchDir dir;
  const fs::path out = dir.path() / "out";
  const CliResult r =
      run_cli(fmt::format("slice {} -o {} --layers 100:102 -q",
                          shell_quote(examples_dir() / "scenes" / "quick_start.json"), shell_quote(out)),
              "", "", "trap '' XFSZ; ulimit -f 4;");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find((out / "slice_0000").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(while the estimate wrote its sample layers under "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("trivox-estimate"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace trivox::test
