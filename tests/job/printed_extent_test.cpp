// The printed extent: the box of the voxels with a material, in pixels (against a plain scan
// of every pixel) and in millimetres (a box prints within a voxel of its size), in stats.json.
#include "trivox/job/printed_extent.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "slice/slice_fixtures.h"
#include "trivox/job/job.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// The reference: every pixel looked at.
PrintedExtent scanned_extent(const LabelImage& labels, int layer) {
  PrintedExtent e;
  for (int y = 0; y < labels.height_px(); ++y)
    for (int x = 0; x < labels.width_px(); ++x)
      if (labels.at(x, y) != LabelImage::kVoid) {
        e.col_lo = std::min(e.col_lo, x);
        e.col_hi = std::max(e.col_hi, x);
        e.row_lo = std::min(e.row_lo, y);
        e.row_hi = std::max(e.row_hi, y);
        e.layer_lo = e.layer_hi = layer;
      }
  return e;
}

void expect_same(const PrintedExtent& a, const PrintedExtent& b) {
  EXPECT_EQ(a.empty(), b.empty());
  if (a.empty() || b.empty()) return;
  EXPECT_EQ(a.col_lo, b.col_lo);
  EXPECT_EQ(a.col_hi, b.col_hi);
  EXPECT_EQ(a.row_lo, b.row_lo);
  EXPECT_EQ(a.row_hi, b.row_hi);
  EXPECT_EQ(a.layer_lo, b.layer_lo);
  EXPECT_EQ(a.layer_hi, b.layer_hi);
}

// Widths around the eight-byte steps, sparse pixels anywhere (the first and last column
// included), and empty images.
TEST(PrintedExtent, AgreesWithAScanOfEveryPixel) {
  std::mt19937 rng(7);
  for (int width = 1; width <= 40; ++width)
    for (int trial = 0; trial < 20; ++trial) {
      SCOPED_TRACE(fmt::format("width {} trial {}", width, trial));
      LabelImage labels(width, 5, LabelImage::kVoid);
      const int count = static_cast<int>(rng() % 4);
      for (int k = 0; k < count; ++k)
        labels.at(static_cast<int>(rng() % static_cast<unsigned>(width)), static_cast<int>(rng() % 5)) =
            static_cast<std::uint8_t>(1 + rng() % 3);
      expect_same(printed_extent(labels, trial), scanned_extent(labels, trial));
    }
}

TEST(PrintedExtent, AddsLayersAndGivesWholeVoxelsInMillimetres) {
  LabelImage a(10, 4, LabelImage::kVoid), b(10, 4, LabelImage::kVoid);
  a.at(2, 1) = 1;
  b.at(7, 3) = 2;
  PrintedExtent e = printed_extent(a, 4);
  e.add(printed_extent(b, 9));
  e.add(printed_extent(LabelImage(10, 4, LabelImage::kVoid), 20));  // an empty layer adds nothing
  EXPECT_EQ(e.col_lo, 2);
  EXPECT_EQ(e.col_hi, 7);
  EXPECT_EQ(e.row_lo, 1);
  EXPECT_EQ(e.row_hi, 3);
  EXPECT_EQ(e.layer_lo, 4);
  EXPECT_EQ(e.layer_hi, 9);
  SliceLayout L;
  L.x0_mm = 1;
  L.y_top_mm = 10;
  L.z0_mm = -1;
  L.pitch_x_mm = 0.5;
  L.pitch_y_mm = 0.25;
  L.layer_mm = 0.1;
  const Box3 box = printed_box_mm(e, L);
  // Within rounding: the sum is formed in another order (or fused) in some builds, and one
  // side is 0 (-1 + 10 * 0.1), where a relative comparison allows nothing.
  EXPECT_NEAR(box.lo.x, 1 + 2 * 0.5, 1e-12);
  EXPECT_NEAR(box.hi.x, 1 + 8 * 0.5, 1e-12);
  EXPECT_NEAR(box.hi.y, 10 - 1 * 0.25, 1e-12);  // row 0 is the top
  EXPECT_NEAR(box.lo.y, 10 - 4 * 0.25, 1e-12);
  EXPECT_NEAR(box.lo.z, -1 + 4 * 0.1, 1e-12);
  EXPECT_NEAR(box.hi.z, -1 + 10 * 0.1, 1e-12);
  EXPECT_TRUE(printed_box_mm(PrintedExtent{}, L).empty());
}

// A 6 x 3 x 0.3 mm box prints within one voxel of its size along each axis, and stats.json
// says so beside the model's box.
TEST(PrintedExtent, StatsJsonGivesThePrintedAndTheModelsSize) {
  const Scene scene = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {6, 3, 0.3}))}, 2);
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-printed-extent-{}", ::getpid());
  fs::remove_all(p.output_dir);
  p.threads = 2;
  const JobStats st = run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  const Box3 printed = printed_box_mm(st.printed, L);
  const double pitch[3] = {L.pitch_x_mm, L.pitch_y_mm, L.layer_mm};
  const double model[3] = {6, 3, 0.3};
  for (int d = 0; d < 3; ++d) {
    SCOPED_TRACE(d);
    EXPECT_LE(std::abs(printed.size()[d] - model[d]), pitch[d] + 1e-9);
    EXPECT_GE(printed.lo[d], -pitch[d]);  // every printed voxel's centre is in the box
    EXPECT_LE(printed.hi[d], model[d] + pitch[d]);
  }
  std::ifstream in(p.output_dir / "stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  const nlohmann::json& extent = stats.at("extent");
  for (int d = 0; d < 3; ++d) {
    EXPECT_DOUBLE_EQ(extent.at("printed").at("size_mm").at(d).get<double>(), printed.size()[d]);
    // The object's box: the volume's tight image, bounded to within a thousandth of a pitch.
    EXPECT_NEAR(extent.at("model").at("size_mm").at(d).get<double>(), model[d], 1e-3 * pitch[d]);
  }
  EXPECT_EQ(extent.at("printed").at("voxels").at(0).get<int>(), st.printed.col_hi - st.printed.col_lo + 1);
  EXPECT_EQ(extent.at("printed").at("voxels").at(2).get<int>(), st.printed.layer_hi - st.printed.layer_lo + 1);
  fs::remove_all(p.output_dir);
}

}  // namespace
}  // namespace trivox
