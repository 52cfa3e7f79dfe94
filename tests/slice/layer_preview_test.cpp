// `--preview`: chosen layers in display colours at their true proportions.
#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/output/display_colours.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

TEST(LayerPreview, ChosenLayersShowEveryVoxelInItsColourWithSquarePixels) {
  const Scene scene = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {6, 3, 0.3}))}, 2);
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-layer-preview-test";
  fs::remove_all(p.output_dir);
  p.min_layers = 0;
  p.preview_layers = {0, L.num_layers - 1};
  const JobStats st = run_slice_job(slicer, p);
  int previews = 0;
  for (const std::string& f : st.files) previews += f.rfind("preview/layer_", 0) == 0;
  EXPECT_EQ(previews, 2);

  for (int layer : p.preview_layers) {
    const RgbaImage labels_image = read_png_rgba(p.output_dir / fmt::format("slice_{:05d}.png", layer + 1));
    const RgbaImage preview = read_png_rgba(p.output_dir / fmt::format("preview/layer_{:05d}.png", layer + 1));
    // 600 x 300 dpi: every image row shows twice, so the pixels are square.
    const int repeat = static_cast<int>(std::lround(L.pitch_y_mm / L.pitch_x_mm));
    ASSERT_EQ(repeat, 2);
    ASSERT_EQ(preview.width_px, labels_image.width_px);
    ASSERT_EQ(preview.height_px, labels_image.height_px * repeat);
    int coloured = 0;
    for (int y = 0; y < preview.height_px; ++y)
      for (int x = 0; x < preview.width_px; ++x) {
        const auto at = [](const RgbaImage& im, int px, int py, int c) {
          return im.rgba[4 * (static_cast<std::size_t>(py) * static_cast<std::size_t>(im.width_px) +
                              static_cast<std::size_t>(px)) +
                         static_cast<std::size_t>(c)];
        };
        // The same colour as the Voxel Print pixel it shows, made opaque.
        for (int c = 0; c < 3; ++c) ASSERT_EQ(at(preview, x, y, c), at(labels_image, x, y / repeat, c));
        ASSERT_EQ(at(preview, x, y, 3), 255);
        coloured += at(labels_image, x, y / repeat, 0) != 255 || at(labels_image, x, y / repeat, 1) != 255;
      }
    EXPECT_GT(coloured, 1000);
  }
  // Layers not chosen have no preview.
  EXPECT_FALSE(fs::exists(p.output_dir / "preview/layer_00002.png"));

  JobParams outside = p;
  outside.preview_layers = {L.num_layers};
  EXPECT_THROW(run_slice_job(slicer, outside), Error);
}

// Two materials in nearly the same colour (VeroWhite and Agilus30White): the Voxel Print
// image keeps both exact colours, the preview and the cuts show them clearly apart.
TEST(LayerPreview, NearlyEqualColoursShowApart) {
  Scene scene = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {6, 3, 0.3}))}, 2);
  scene.materials[0].rgba = {240, 240, 235, 255};
  scene.materials[1].rgba = {232, 232, 228, 255};
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-layer-preview-similar";
  fs::remove_all(p.output_dir);
  p.min_layers = 0;
  p.formats = {"voxelprint", "preview"};
  p.preview_layers = {2};
  run_slice_job(slicer, p);
  const auto colours = [](const RgbaImage& im) {
    std::set<Rgb> found;
    for (std::size_t i = 0; i < im.rgba.size(); i += 4) found.insert({im.rgba[i], im.rgba[i + 1], im.rgba[i + 2]});
    return found;
  };
  const std::set<Rgb> exact = colours(read_png_rgba(p.output_dir / "slice_00003.png"));
  EXPECT_TRUE(exact.count({240, 240, 235}) && exact.count({232, 232, 228}));
  for (const char* name : {"preview/layer_00003.png", "preview/cut_xz.png"}) {
    SCOPED_TRACE(name);
    std::set<Rgb> shown = colours(read_png_rgba(p.output_dir / name));
    shown.erase({255, 255, 255});  // the background
    shown.erase({128, 128, 128});  // the contact sheet's grid, if any
    ASSERT_EQ(shown.size(), 2u);
    EXPECT_GE(colour_difference(*shown.begin(), *shown.rbegin()), kDisplayColourSeparation);
  }
}

TEST(LayerPreview, CommandLineOption) {
  const fs::path dir = fs::temp_directory_path() / "trivox-layer-preview-cli";
  fs::remove_all(dir);
  const std::string scene = std::string(TRIVOX_EXAMPLES_DIR) + "/scenes/quick_start.json";
  const test::CliResult ok =
      test::run_cli(fmt::format("slice {} -o {} --layers 10:12 --preview 10,12 -q", scene, dir.string()));
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(dir / "preview/layer_00010.png"));
  EXPECT_TRUE(fs::exists(dir / "preview/layer_00012.png"));
  EXPECT_FALSE(fs::exists(dir / "preview/layer_00011.png"));
  const test::CliResult bad =
      test::run_cli(fmt::format("slice {} -o {}-bad --layers 10:12 --preview 40 -q", scene, dir.string()));
  EXPECT_EQ(bad.exit_code, 3) << bad.err;
  EXPECT_NE(bad.err.find("preview layer 40"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace trivox
