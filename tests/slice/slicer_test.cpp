// The slicer against analytic regions and fractions (issue: slicing tests 1, 2 and 5).
#include "trivox/slice/slicer.h"

#include <cmath>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"

namespace trivox {
namespace {

using test::box_volume;

// Every pixel whose centre is farther than one pixel from the region's boundary must be
// inside exactly when its centre is inside the region.
template <class InsideFn, class DistanceFn>
void expect_matches_region(const Slicer& slicer, int layer, InsideFn inside_region, DistanceFn boundary_distance) {
  const SliceLayout& L = slicer.layout();
  const LayerResult r = slicer.slice_layer(layer);
  const double z = L.z_of_layer(layer);
  const double pixel = std::max(L.pitch_x_mm, L.pitch_y_mm);
  int checked = 0, wrong = 0;
  for (int row = 0; row < L.height_px; ++row)
    for (int col = 0; col < L.width_px; ++col) {
      const Vec3 c{L.x_of_col(col), L.y_of_row(row), z};
      if (boundary_distance(c) < pixel) continue;
      ++checked;
      const bool marked = r.labels.at(col, row) != LabelImage::kVoid;
      if (marked != inside_region(c) && ++wrong < 5)
        ADD_FAILURE() << "pixel " << col << "," << row << " at " << c.x << "," << c.y << " marked " << marked;
    }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(checked, 1000);
  EXPECT_EQ(r.stats.folded_pixels, 0);
  EXPECT_EQ(r.stats.unresolved_pixels, 0);
}

TEST(Slicer, BoxMarksExactlyThePixelsInside) {
  const Vec3 lo{1.03, 0.57, 0.0}, hi{9.71, 5.2, 3.0};
  const Scene scene = test::scene_with({test::constant_cell(box_volume(lo, hi), 0, 1)}, 1);
  const Slicer slicer(scene, {});
  expect_matches_region(
      slicer, slicer.layout().num_layers / 2,
      [&](Vec3 p) { return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y; },
      [&](Vec3 p) { return std::min({std::abs(p.x - lo.x), std::abs(p.x - hi.x), std::abs(p.y - lo.y), std::abs(p.y - hi.y)}); });
}

TEST(Slicer, RationalAnnulusSectorMarksExactlyThePixelsInside) {
  // A quarter annulus of radii 2 and 6 mm, 1 mm high: exact NURBS, so the region is exact.
  const Scene scene = test::scene_with({test::constant_cell(test::annulus_sector(2.0, 6.0, 1.0), 0, 1)}, 1);
  const Slicer slicer(scene, {});
  for (int layer : {0, slicer.layout().num_layers / 3}) {
    expect_matches_region(
        slicer, layer,
        [](Vec3 p) {
          const double r = std::hypot(p.x, p.y);
          return p.x >= 0 && p.y >= 0 && r >= 2.0 && r <= 6.0;
        },
        [](Vec3 p) {
          const double r = std::hypot(p.x, p.y);
          return std::min({std::abs(r - 2.0), std::abs(r - 6.0), std::abs(p.x), std::abs(p.y)});
        });
  }
}

TEST(Slicer, SolidCylinderSectorWithCollapsedAxis) {
  const Scene scene = test::scene_with({test::constant_cell(test::cylinder_sector(5.0, 1.0), 0, 1)}, 1);
  const Slicer slicer(scene, {});
  expect_matches_region(
      slicer, 3, [](Vec3 p) { return p.x >= 0 && p.y >= 0 && std::hypot(p.x, p.y) <= 5.0; },
      [](Vec3 p) { return std::min({std::abs(std::hypot(p.x, p.y) - 5.0), std::abs(p.x), std::abs(p.y)}); });
}

TEST(Slicer, GradientWindowsKeepTheirFractions) {
  // 30 x 12 mm: 709 x 142 pixels at 600 x 300 dpi; material 0 goes from 0 to 1 along x.
  const Vec3 lo{0, 0, 0}, hi{30, 12, 1};
  const Scene scene = test::scene_with({test::gradient_cell(box_volume(lo, hi))}, 2);
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const LayerResult r = slicer.slice_layer(L.num_layers / 2);
  int windows = 0;
  for (int r0 = 0; r0 + 64 <= L.height_px; r0 += 64)
    for (int c0 = 0; c0 + 64 <= L.width_px; c0 += 64) {
      // Only windows whose pixels all lie inside the box (centres more than a pixel in).
      if (L.x_of_col(c0) < lo.x + 0.1 || L.x_of_col(c0 + 63) > hi.x - 0.1 || L.y_of_row(r0) > hi.y - 0.1 ||
          L.y_of_row(r0 + 63) < lo.y + 0.1)
        continue;
      double expected = 0;
      int count0 = 0, count1 = 0;
      for (int row = r0; row < r0 + 64; ++row)
        for (int col = c0; col < c0 + 64; ++col) {
          expected += (L.x_of_col(col) - lo.x) / (hi.x - lo.x);
          const std::uint8_t label = r.labels.at(col, row);
          count0 += label == LabelImage::label_of_material(0);
          count1 += label == LabelImage::label_of_material(1);
        }
      expected /= 64 * 64;
      EXPECT_NEAR(count0 / 4096.0, expected, 0.01) << "window at " << c0 << "," << r0;
      EXPECT_NEAR(count1 / 4096.0, 1 - expected, 0.01);
      EXPECT_EQ(count0 + count1, 4096);  // no void inside
      ++windows;
    }
  EXPECT_GE(windows, 10);
}

TEST(Slicer, TracingStrategiesReduceGlobalSolvesAsInTable1) {
  // A bundled-class cubic volume: the twisted, bent 8x8x8 column, 8 x 6 x 5 mm.
  const Scene scene = test::scene_with({test::constant_cell(test::twisted_bent_box(8, 6, 5), 0, 1)}, 1);
  std::vector<double> share;
  std::int64_t inside = -1;
  for (TracingStrategy s : {TracingStrategy::kNone, TracingStrategy::kPreviousPoint, TracingStrategy::kPreviousLine,
                            TracingStrategy::kFull, TracingStrategy::kPredict, TracingStrategy::kFlood}) {
    SliceParams p;
    p.tracing = s;
    const Slicer slicer(scene, p);
    const LayerResult r = slicer.slice_layer(slicer.layout().num_layers / 2);
    if (inside < 0) inside = r.stats.pixels_inside;
    EXPECT_EQ(r.stats.pixels_inside, inside) << to_string(s);  // the same pixels whatever the seeds
    share.push_back(static_cast<double>(r.stats.global_calls) / static_cast<double>(r.stats.pixels_inside));
  }
  EXPECT_GE(share[0], 1.0);  // none: every pixel (and the outside candidates) globally
  EXPECT_LT(share[1], share[0]);
  EXPECT_LT(share[2], share[1]);
  EXPECT_LE(share[3], share[2]);
  EXPECT_LT(share[3], 0.02);
  // trivox's own strategies: the row predictor changes the work, not the seeds' reach; the
  // flood seeds reach spans the 8-neighbours cannot.
  EXPECT_LE(share[4], share[3] * 1.01);
  EXPECT_LT(share[5], share[4]);
}

// The outline only chooses which pixels to invert: a finer one leaves fewer candidates just
// outside the cell to prove outside, and every pixel is still inside exactly when the global
// solver finds its centre a preimage.
TEST(Slicer, OutlineToleranceChangesTheWorkNotThePixels) {
  const Volume column = test::twisted_bent_box(8, 6, 5);
  const GlobalSolver solver(column);
  const Scene scene = test::scene_with({test::constant_cell(column, 0, 1)}, 1);
  std::int64_t last_globals = -1, last_candidates = -1;
  for (double tolerance : {0.0035, 0.0015, 0.0006}) {
    SliceParams p;
    p.outline_tolerance_mm = tolerance;
    const Slicer slicer(scene, p);
    const SliceLayout& L = slicer.layout();
    std::int64_t globals = 0, candidates = 0;
    int wrong = 0;
    for (int layer : {L.num_layers / 4, L.num_layers / 2}) {
      const LayerResult r = slicer.slice_layer(layer);
      globals += r.stats.global_calls;
      candidates += r.stats.candidates;
      EXPECT_EQ(r.stats.unresolved_pixels, 0);
      for (int row = 0; row < L.height_px; ++row)
        for (int col = 0; col < L.width_px; ++col) {
          const bool inside = r.labels.at(col, row) != LabelImage::kVoid;
          const bool reference = !solver.solve({L.x_of_col(col), L.y_of_row(row), L.z_of_layer(layer)}).preimages.empty();
          if (inside != reference && ++wrong < 5) ADD_FAILURE() << tolerance << ": pixel " << col << "," << row;
        }
    }
    EXPECT_EQ(wrong, 0) << tolerance;
    if (last_globals >= 0) {
      EXPECT_LT(globals, last_globals) << tolerance;
      EXPECT_LT(candidates, last_candidates) << tolerance;
    }
    last_globals = globals;
    last_candidates = candidates;
  }
}

TEST(Slicer, LastCellWithMaterialWins) {
  // Two overlapping boxes: the second cell owns the overlap.
  const Scene scene = test::scene_with({test::constant_cell(box_volume({0, 0, 0}, {6, 4, 1}), 0, 2, "a"),
                                        test::constant_cell(box_volume({3, 0, 0}, {9, 4, 1}), 1, 2, "b")},
                                       2);
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const LayerResult r = slicer.slice_layer(2);
  const int row = L.height_px / 2;
  auto label_at_x = [&](double x) { return r.labels.at(static_cast<int>(std::lround(L.col_of_x(x))), row); };
  EXPECT_EQ(label_at_x(1.5), LabelImage::label_of_material(0));
  EXPECT_EQ(label_at_x(4.5), LabelImage::label_of_material(1));
  EXPECT_EQ(label_at_x(7.5), LabelImage::label_of_material(1));
}

}  // namespace
}  // namespace trivox
