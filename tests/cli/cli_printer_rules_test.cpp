// The rules of GrabCAD Voxel Print hold whatever a printer profile says (docs/CLI.md,
// "slice"): a Voxel Print stack or package ("voxelprint", "gcvf") holds at most 6 material
// colours, 3 in High Speed mode, even when a custom profile raises max_materials; a stack of
// fewer than the 30 layers it needs is written only when --min-layers asks for it, and the
// summary and the manifest say so; --min-layers has an upper bound.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "cli_small_scene.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> material_names(int n) {
  std::vector<std::string> names;
  for (int i = 0; i < n; ++i) names.push_back(fmt::format("m{}", i));
  return names;
}

TEST(CliPrinterRules, VoxelPrintNeverTakesMoreColoursThanItsModePrintsWhateverTheProfileSays) {
  const struct {
    const char* base;
    int materials, limit;
    const char* mode;
  } cases[] = {{"j750-hm", 8, 6, "High Mix"}, {"j750-hq", 7, 6, "High Quality"}, {"j850-hs", 4, 3, "High Speed"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.base);
    ScratchDir dir;
    write_text(dir.path() / "wide.json",
               small_box_scene(material_names(c.materials), 4,
                               fmt::format(R"({{"base": "{}", "max_materials": 10, "name": "wide"}})", c.base)));
    for (const char* format : {"voxelprint", "gcvf"}) {
      const CliResult r =
          run_cli(fmt::format("slice {} -o {} --layers 1:2 -q --format {}", shell_quote(dir.path() / "wide.json"),
                              shell_quote(dir.path() / "out"), format));
      EXPECT_EQ(r.exit_code, 3) << format << ": " << r.err;
      EXPECT_NE(r.err.find(fmt::format("wide.json: the scene uses {} materials, but GrabCAD Voxel Print (output "
                                       "'{}') prints at most {} per job in {} mode (printer profile 'wide' says 10)",
                                       c.materials, format, c.limit, c.mode)),
                std::string::npos)
          << r.err;
      EXPECT_FALSE(fs::exists(dir.path() / "out"));
    }
    // Outputs without the colour limit take what the profile allows.
    const CliResult bitmaps =
        run_cli(fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q --format bitmaps",
                            shell_quote(dir.path() / "wide.json"), shell_quote(dir.path() / "out")));
    EXPECT_EQ(bitmaps.exit_code, 0) << bitmaps.err;
  }
  // At the limit it slices.
  ScratchDir dir;
  write_text(dir.path() / "three.json",
             small_box_scene(material_names(3), 4, R"({"base": "j750-hs", "max_materials": 10})"));
  const CliResult r = run_cli(fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q --format voxelprint,gcvf",
                                          shell_quote(dir.path() / "three.json"), shell_quote(dir.path() / "out")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(CliPrinterRules, AStackShorterThanVoxelPrintNeedsIsWrittenOnlyWhenAskedAndReported) {
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene());
  const auto slice = [&](const std::string& out, const std::string& options) {
    return run_cli(fmt::format("slice {} -o {} --layers 1:3 -q {}", shell_quote(dir.path() / "box.json"),
                               shell_quote(dir.path() / out), options));
  };
  // By default the stack is padded to 30 layers.
  const CliResult padded = slice("padded", "");
  ASSERT_EQ(padded.exit_code, 0) << padded.err;
  EXPECT_TRUE(fs::exists(dir.path() / "padded" / "slice_00030.png"));
  EXPECT_NE(padded.out.find("padded with 27 empty layers"), std::string::npos) << padded.out;
  EXPECT_EQ(padded.out.find("fewer than the 30"), std::string::npos) << padded.out;
  // --min-layers 0: three layers, and the summary and the manifest say so.
  const CliResult shorter = slice("short", "--min-layers 0");
  ASSERT_EQ(shorter.exit_code, 0) << shorter.err;
  EXPECT_TRUE(fs::exists(dir.path() / "short" / "slice_00003.png"));
  EXPECT_FALSE(fs::exists(dir.path() / "short" / "slice_00004.png"));
  EXPECT_NE(shorter.out.find("note: the stack has 3 layers, fewer than the 30 GrabCAD Voxel Print needs, as "
                             "--min-layers 0 asked (manifest.json records min_layers 0)"),
            std::string::npos)
      << shorter.out;
  const nlohmann::json m = nlohmann::json::parse(read_text(dir.path() / "short" / "manifest.json"));
  EXPECT_EQ(m.at("settings").at("min_layers"), "0");
  // No note for outputs that are not for Voxel Print.
  const CliResult bitmaps = slice("bitmaps", "--min-layers 0 --format bitmaps");
  ASSERT_EQ(bitmaps.exit_code, 0) << bitmaps.err;
  EXPECT_EQ(bitmaps.out.find("fewer than the 30"), std::string::npos) << bitmaps.out;
  // The bound: at most 1000 layers of padding are asked for.
  for (const char* value : {"1001", "-1", "2000000000"}) {
    const CliResult r = slice("bound", fmt::format("--min-layers {}", value));
    EXPECT_EQ(r.exit_code, 2) << value << ": " << r.err;
    EXPECT_NE(r.err.find("--min-layers"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "bound"));
  }
}

}  // namespace
}  // namespace trivox::test
