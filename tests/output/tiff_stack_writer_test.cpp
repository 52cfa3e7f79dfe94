// The "tiff" stack output: every page decodes to the labels of its layer image, in layer
// order; the file is identical for 1 and 3 threads and after a stop and resume.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/detail/tiff_stack.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

Scene tiff_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.15}))}, 2);
  s.source = "tiff-scene";
  return s;
}

JobParams tiff_params(const std::string& name, int threads) {
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-tiff-test-{}-{}", ::getpid(), name);
  fs::remove_all(p.output_dir);
  p.threads = threads;
  p.formats = {"voxelprint", "tiff"};
  p.manifest_interval_seconds = 0;
  return p;
}

TEST(TiffStackWriter, PagesAreTheLayersInOrder) {
  const Scene scene = tiff_scene();
  const Slicer slicer(scene, {});
  const JobParams p = tiff_params("pages", 3);
  run_slice_job(slicer, p);
  std::vector<std::array<std::uint8_t, 4>> palette = {job_background(scene, p)};
  for (const MaterialDef& m : scene.materials) palette.push_back(m.rgba);
  std::int64_t material_pixels = 0;
  const int pages = read_tiff_stack(p.output_dir / "tiff/stack.tif", [&](int page, const LabelImage& labels) {
    const RgbaImage rgba = read_png_rgba(p.output_dir / fmt::format("slice_{}.png", layer_number(page, 30)));
    ASSERT_EQ(labels.width_px(), rgba.width_px);
    ASSERT_EQ(labels.height_px(), rgba.height_px);
    for (std::size_t px = 0; px < labels.values().size(); ++px) {
      const std::uint8_t l = labels.values()[px];
      ASSERT_LT(l, palette.size());
      ASSERT_TRUE(
          std::equal(palette[l].begin(), palette[l].end(), rgba.rgba.begin() + static_cast<std::ptrdiff_t>(4 * px)))
          << "page " << page << " pixel " << px;
      material_pixels += l != 0;
    }
  });
  EXPECT_EQ(pages, 30);
  EXPECT_GT(material_pixels, 0);
  EXPECT_TRUE(verify_output(p.output_dir).ok());
  EXPECT_FALSE(fs::exists(p.output_dir / "tiff/stack.tif.spool"));
  fs::remove_all(p.output_dir);
}

TEST(TiffStackWriter, IdenticalForOneAndThreeThreadsAndAfterResume) {
  const Scene scene = tiff_scene();
  const Slicer slicer(scene, {});
  const JobParams a = tiff_params("t1", 1);
  run_slice_job(slicer, a);
  const JobParams b = tiff_params("t3", 3);
  EXPECT_TRUE(test::slice_until_stopped(slicer, b, 9).interrupted);
  EXPECT_FALSE(fs::exists(b.output_dir / "tiff/stack.tif"));
  test::slice_resumed(slicer, b);
  EXPECT_EQ(read_bytes(a.output_dir / "tiff/stack.tif"), read_bytes(b.output_dir / "tiff/stack.tif"));
  EXPECT_EQ(read_bytes(a.output_dir / "manifest.json"), read_bytes(b.output_dir / "manifest.json"));
  // A damaged stack is caught by verify.
  std::string bytes = read_bytes(b.output_dir / "tiff/stack.tif");
  std::ofstream(b.output_dir / "tiff/stack.tif", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_FALSE(verify_output(b.output_dir).ok());
  EXPECT_THROW(read_tiff_stack(b.output_dir / "tiff/stack.tif", [](int, const LabelImage&) {}), Error);
  fs::remove_all(a.output_dir);
  fs::remove_all(b.output_dir);
}

}  // namespace
}  // namespace trivox
