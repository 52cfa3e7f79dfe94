// The "preview" stack output: the cuts against a reference built from the whole decoded
// stack, determinism, resume, and what a shard writes for it.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

Scene preview_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {4, 2, 0.4}))}, 2);
  s.cells.push_back(test::constant_cell(
      Volume(test::annulus_sector(0.5, 1.5, 0.3).spline().transformed([](std::span<double> q) { q[0] += 2; })), 0, 2,
      "ring"));
  return s;
}

JobParams preview_params(const std::string& name, int threads) {
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-preview-test-{}-{}", ::getpid(), name);
  fs::remove_all(p.output_dir);
  p.threads = threads;
  p.formats = {"voxelprint", "preview"};
  p.manifest_interval_seconds = 0;
  return p;
}

// Nearest-neighbour index at the centre of target sample i of m over n source samples.
int nearest(int i, int m, int n) {
  return std::min(n - 1, static_cast<int>((2 * i + 1) * static_cast<std::int64_t>(n) / (2 * m)));
}

TEST(PreviewWriter, CutsMatchTheDecodedStackAndFilesAreListed) {
  const Scene scene = preview_scene();
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const JobParams p = preview_params("cuts", 2);
  run_slice_job(slicer, p);
  const VerifyReport report = verify_output(p.output_dir);
  EXPECT_TRUE(report.ok());
  int stack_files = 0;
  for (const ManifestFile& f : report.manifest.files) stack_files += f.layer == 0;
  EXPECT_EQ(stack_files, 5);  // the four previews and materials.csv

  // The x-z cut: the middle row of every model layer, top layer at the top, resampled to the
  // coarsest pitch; colours are the layer images' colours made opaque.
  const int layers = L.num_layers;
  std::vector<RgbaImage> stack;
  for (int i = 0; i < layers; ++i)
    stack.push_back(read_png_rgba(p.output_dir / fmt::format("slice_{}.png", layer_number(i, 30))));
  const double pitch = std::max({L.pitch_x_mm, L.pitch_y_mm, L.layer_mm});
  const RgbaImage xz = read_png_rgba(p.output_dir / "preview/cut_xz.png");
  EXPECT_EQ(xz.width_px, static_cast<int>(std::lround(L.width_px * L.pitch_x_mm / pitch)));
  EXPECT_EQ(xz.height_px, std::max(1, static_cast<int>(std::lround(layers * L.layer_mm / pitch))));
  int material_pixels = 0;
  for (int y = 0; y < xz.height_px; ++y) {
    const RgbaImage& layer = stack[static_cast<std::size_t>(layers - 1 - nearest(y, xz.height_px, layers))];
    for (int x = 0; x < xz.width_px; ++x) {
      const std::size_t src = 4 * (static_cast<std::size_t>(L.height_px / 2) * static_cast<std::size_t>(L.width_px) +
                                   static_cast<std::size_t>(nearest(x, xz.width_px, L.width_px)));
      const std::size_t dst =
          4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(xz.width_px) + static_cast<std::size_t>(x));
      for (int c = 0; c < 3; ++c) ASSERT_EQ(xz.rgba[dst + c], layer.rgba[src + c]) << x << "," << y;
      EXPECT_EQ(xz.rgba[dst + 3], 255);
      material_pixels += layer.rgba[src] != 255 || layer.rgba[src + 1] != 255 || layer.rgba[src + 2] != 255;
    }
  }
  EXPECT_GT(material_pixels, 0);
  // The x-y cut is the middle model layer.
  const RgbaImage xy = read_png_rgba(p.output_dir / "preview/cut_xy.png");
  const RgbaImage& mid = stack[static_cast<std::size_t>(layers / 2)];
  for (int y = 0; y < xy.height_px; ++y)
    for (int x = 0; x < xy.width_px; ++x) {
      const std::size_t src =
          4 * (static_cast<std::size_t>(nearest(y, xy.height_px, L.height_px)) * static_cast<std::size_t>(L.width_px) +
               static_cast<std::size_t>(nearest(x, xy.width_px, L.width_px)));
      const std::size_t dst =
          4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(xy.width_px) + static_cast<std::size_t>(x));
      for (int c = 0; c < 3; ++c) ASSERT_EQ(xy.rgba[dst + c], mid.rgba[src + c]);
    }
  const RgbaImage sheet = read_png_rgba(p.output_dir / "preview/contact_sheet.png");
  EXPECT_GT(sheet.width_px, 0);
  fs::remove_all(p.output_dir);
}

TEST(PreviewWriter, IdenticalForOneAndThreeThreadsAndAfterResume) {
  const Scene scene = preview_scene();
  const Slicer slicer(scene, {});
  const JobParams a = preview_params("t1", 1);
  run_slice_job(slicer, a);
  const JobParams b = preview_params("t3", 3);
  EXPECT_TRUE(test::slice_until_stopped(slicer, b, 7).interrupted);
  EXPECT_FALSE(fs::exists(b.output_dir / "preview/cut_xz.png"));  // stack files only when complete
  test::slice_resumed(slicer, b);
  for (const char* f : {"contact_sheet.png", "cut_xy.png", "cut_xz.png", "cut_yz.png"})
    EXPECT_EQ(read_bytes(a.output_dir / "preview" / f), read_bytes(b.output_dir / "preview" / f)) << f;
  EXPECT_EQ(read_bytes(a.output_dir / "manifest.json"), read_bytes(b.output_dir / "manifest.json"));
  fs::remove_all(a.output_dir);
  fs::remove_all(b.output_dir);
}

// A dark material (Agilus30Black's #282828) on the printer images' black would be lost in the
// previews: they take a background apart from every material (white here), while the printer
// images keep black; a layer preview and the contact sheet both show it.
TEST(PreviewWriter, ADarkMaterialIsShownOnABackgroundApartFromIt) {
  Scene scene = preview_scene();
  scene.materials[0].rgba = {40, 40, 40, 255};
  scene.materials[1].rgba = {30, 30, 30, 255};
  const Slicer slicer(scene, {});
  JobParams p = preview_params("dark", 2);
  p.preview_layers = {0};
  run_slice_job(slicer, p);
  EXPECT_EQ(job_background(scene, p), (std::array<std::uint8_t, 4>{0, 0, 0, 255}));
  EXPECT_EQ(job_preview_background(scene, p), (std::array<std::uint8_t, 4>{255, 255, 255, 255}));
  const RgbaImage printer = read_png_rgba(p.output_dir / "slice_00001.png");
  EXPECT_EQ(printer.rgba[0], 0);  // a corner outside the object: black in the printer's image
  const RgbaImage layer = read_png_rgba(p.output_dir / "preview" / "layer_00001.png");
  EXPECT_EQ(layer.rgba[0], 255);  // the same corner: white in the layer's preview
  EXPECT_EQ(layer.rgba[1], 255);
  // The contact sheet (grey lines between its thumbnails): white around the parts, no black.
  const RgbaImage sheet = read_png_rgba(p.output_dir / "preview" / "contact_sheet.png");
  std::int64_t white = 0, black = 0;
  for (std::size_t i = 0; i < sheet.rgba.size(); i += 4) {
    white += sheet.rgba[i] == 255 && sheet.rgba[i + 1] == 255 && sheet.rgba[i + 2] == 255;
    black += sheet.rgba[i] == 0 && sheet.rgba[i + 1] == 0 && sheet.rgba[i + 2] == 0;
  }
  EXPECT_GT(white, 0);
  EXPECT_EQ(black, 0);
  // One given with --background is the previews' too.
  p.background_rgba = std::array<std::uint8_t, 4>{0, 0, 0, 255};
  EXPECT_EQ(job_preview_background(scene, p), (std::array<std::uint8_t, 4>{0, 0, 0, 255}));
  fs::remove_all(p.output_dir);
}

TEST(PreviewWriter, AShardKeepsItsLayersForThePreviewsOfTheMergedJob) {
  const Scene scene = preview_scene();
  const Slicer slicer(scene, {});
  JobParams p = preview_params("shard", 1);
  p.shard_index = 1;
  p.shard_count = 2;
  run_slice_job(slicer, p);  // the merged job's resume writes them (tests/job/stack_parts_test.cpp)
  EXPECT_FALSE(fs::exists(p.output_dir / "preview"));
  EXPECT_TRUE(fs::is_directory(p.output_dir / "stack_parts"));
  fs::remove_all(p.output_dir);
}

}  // namespace
}  // namespace trivox
