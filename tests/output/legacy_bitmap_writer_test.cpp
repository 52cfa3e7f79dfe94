// The "legacy" output: 1-bit BMPs read back with an independent decoder and compared with the
// RGBA layer images; the text manifest; shards merged equal one run.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

struct Bmp1 {
  int width = 0, height = 0;
  std::vector<int> bits;  // row-major, top row first
};

// Straight from the BMP layout: little-endian fields, rows bottom-up padded to 4 bytes.
Bmp1 decode_bmp1(const std::string& b) {
  const auto le = [&](std::size_t at, int n) {
    std::uint32_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = v * 256 + static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
    return v;
  };
  EXPECT_EQ(b.substr(0, 2), "BM");
  EXPECT_EQ(le(2, 4), b.size());
  EXPECT_EQ(le(14, 4), 40u);
  EXPECT_EQ(le(28, 2), 1u);                         // bits per pixel
  EXPECT_EQ(le(30, 4), 0u);                         // uncompressed
  EXPECT_EQ(le(54 + 4, 4) & 0xffffffu, 0xffffffu);  // palette entry 1 is white
  Bmp1 img;
  img.width = static_cast<int>(le(18, 4));
  img.height = static_cast<int>(le(22, 4));
  const std::size_t offset = le(10, 4), stride = (static_cast<std::size_t>(img.width) + 31) / 32 * 4;
  for (int y = 0; y < img.height; ++y) {
    const std::size_t row = offset + static_cast<std::size_t>(img.height - 1 - y) * stride;
    for (int x = 0; x < img.width; ++x)
      img.bits.push_back((static_cast<unsigned char>(b[row + static_cast<std::size_t>(x / 8)]) >> (7 - x % 8)) & 1);
  }
  return img;
}

Scene legacy_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.1}))}, 2);
  s.source = "legacy-scene";
  return s;
}

TEST(LegacyBitmapWriter, BitmapsMatchTheRgbaLayersAndTheTextListsThem) {
  const Scene scene = legacy_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-legacy-test";
  fs::remove_all(p.output_dir);
  p.formats = {"voxelprint", "legacy"};
  run_slice_job(slicer, p);
  std::int64_t material_pixels = 0;
  for (int i = 0; i < 30; ++i) {
    const std::string num = layer_number(i, 30);
    const RgbaImage rgba = read_png_rgba(p.output_dir / fmt::format("slice_{}.png", num));
    for (int j = 0; j < 2; ++j) {
      const Bmp1 bmp = decode_bmp1(read_bytes(p.output_dir / fmt::format("legacy/slice_{}_m{}.bmp", num, j)));
      ASSERT_EQ(bmp.width, rgba.width_px);
      ASSERT_EQ(bmp.height, rgba.height_px);
      for (std::size_t px = 0; px < bmp.bits.size(); ++px) {
        const bool is_material = std::equal(scene.materials[static_cast<std::size_t>(j)].rgba.begin(),
                                            scene.materials[static_cast<std::size_t>(j)].rgba.end(),
                                            rgba.rgba.begin() + static_cast<std::ptrdiff_t>(4 * px));
        ASSERT_EQ(bmp.bits[px] == 1, is_material) << "layer " << i << " material " << j << " pixel " << px;
        material_pixels += bmp.bits[px];
      }
    }
  }
  EXPECT_GT(material_pixels, 0);
  std::istringstream text(read_bytes(p.output_dir / "legacy/slices.txt"));
  int slices = 0;
  bool thickness = false, count = false;
  for (std::string line; std::getline(text, line);) {
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "layer_thickness_mm") {
      double t = 0;
      words >> t;
      thickness = std::abs(t - slicer.layout().layer_mm) < 1e-12;
    } else if (key == "slice_count") {
      int n = 0;
      words >> n;
      count = n == 30;
    } else if (key == "slice") {
      int n = 0;
      words >> n;
      EXPECT_EQ(n, ++slices);
      for (std::string file; words >> file;) EXPECT_TRUE(fs::exists(p.output_dir / "legacy" / file)) << file;
    }
  }
  EXPECT_TRUE(thickness);
  EXPECT_TRUE(count);
  EXPECT_EQ(slices, 30);
  EXPECT_TRUE(verify_output(p.output_dir).ok());

  // Two shards merged: the same bytes, slices.txt listed once.
  JobParams s = p;
  s.output_dir = fs::temp_directory_path() / "trivox-legacy-test-shards";
  fs::remove_all(s.output_dir);
  for (int i : {1, 2}) {
    s.shard_index = i;
    s.shard_count = 2;
    run_slice_job(slicer, s);
  }
  merge_shards(s.output_dir);
  EXPECT_EQ(read_bytes(p.output_dir / "manifest.json"), read_bytes(s.output_dir / "manifest.json"));
  EXPECT_EQ(read_bytes(p.output_dir / "legacy/slices.txt"), read_bytes(s.output_dir / "legacy/slices.txt"));
  fs::remove_all(p.output_dir);
  fs::remove_all(s.output_dir);
}

}  // namespace
}  // namespace trivox
