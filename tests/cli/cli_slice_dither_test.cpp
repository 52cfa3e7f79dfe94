// `trivox slice` dithering options over a scene's "dithering" settings, and the
// colour-to-material sheet.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"

namespace trivox::test {
namespace {

const std::string kScene = shell_quote(examples_dir() / "scenes" / "dithering_skin.json");

TEST(CliSliceDither, OptionsOverrideTheScene) {
  ScratchDir dir;
  const CliResult scene_only =
      run_cli("slice " + kScene + " -o " + shell_quote(dir.path() / "a") + " -q --layers 1:2 --min-layers 0");
  ASSERT_EQ(scene_only.exit_code, 0) << scene_only.err;
  const auto a = nlohmann::json::parse(read_text(dir.path() / "a" / "stats.json"));
  EXPECT_EQ(a["dithering"]["method"], "blue-noise");
  EXPECT_EQ(a["dithering"]["skin_voxels"], 2);
  EXPECT_EQ(a["dithering"]["vary_by_layer"], true);

  const CliResult overridden =
      run_cli("slice " + kScene + " -o " + shell_quote(dir.path() / "b") +
              " -q --layers 1:2 --min-layers 0 --dither stucki --skin 0 --vary-by-layer false");
  ASSERT_EQ(overridden.exit_code, 0) << overridden.err;
  const auto b = nlohmann::json::parse(read_text(dir.path() / "b" / "stats.json"));
  EXPECT_EQ(b["dithering"]["method"], "stucki");
  EXPECT_EQ(b["dithering"]["skin_voxels"], 0);
  EXPECT_EQ(b["dithering"]["vary_by_layer"], false);

  // The sheet: a header, the background and the scene's two library materials.
  const std::string sheet = read_text(dir.path() / "b" / "materials.csv");
  EXPECT_EQ(sheet.rfind("label,name,library,hex,r,g,b,a\n0,background,,#000000FF,", 0), 0u) << sheet;
  EXPECT_NE(sheet.find("\n1,VeroCyan,VeroCyan,#00A0E3FF,0,160,227,255\n"), std::string::npos) << sheet;
  EXPECT_NE(sheet.find("\n2,VeroYellow,VeroYellow,#FFED00FF,255,237,0,255\n"), std::string::npos) << sheet;
}

// A greyscale job says how it exposes its greys, and speaks of dithering only for the formats
// that show materials (here the previews), never for the grey levels alone.
TEST(CliSliceDither, AGreyscaleJobSaysHowItsGreysAreMadeNotHowItDithers) {
  ScratchDir dir;
  const std::string scene = shell_quote(examples_dir() / "scenes" / "column_greyscale_sl1s.json");
  const CliResult greys =
      run_cli("slice " + scene + " -o " + shell_quote(dir.path() / "g") + " --layers 1:2 --format greyscale,sl1s");
  ASSERT_EQ(greys.exit_code, 0) << greys.err;
  EXPECT_NE(greys.err.find("trivox: greyscale: the fraction of stiff, edges anti-aliased 4 x 4 sub-samples"),
            std::string::npos)
      << greys.err;
  EXPECT_EQ(greys.err.find("dithering"), std::string::npos) << greys.err;
  const CliResult with_preview =
      run_cli("slice " + scene + " -o " + shell_quote(dir.path() / "p") + " --layers 1:2 --format sl1s,preview");
  ASSERT_EQ(with_preview.exit_code, 0) << with_preview.err;
  EXPECT_NE(with_preview.err.find(", for preview\n"), std::string::npos) << with_preview.err;
}

TEST(CliSliceDither, BadOptionsExit2AndSayWhy) {
  ScratchDir dir;
  const CliResult method = run_cli("slice " + kScene + " -o " + shell_quote(dir.path()) + " -q --dither ordered");
  EXPECT_EQ(method.exit_code, 2);
  EXPECT_NE(method.err.find("--dither must be one of floyd-steinberg, jarvis-judice-ninke, stucki, blue-noise"),
            std::string::npos)
      << method.err;
  const CliResult skin = run_cli("slice " + kScene + " -o " + shell_quote(dir.path()) + " -q --skin 5000");
  EXPECT_EQ(skin.exit_code, 2);
  EXPECT_NE(skin.err.find("--skin"), std::string::npos) << skin.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "slice_00001.png"));
}

}  // namespace
}  // namespace trivox::test
