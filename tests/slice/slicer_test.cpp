// The slicer against analytic regions and fractions (issue: slicing tests 1, 2 and 5).
#include "trivox/slice/slicer.h"

#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/material/material_function.h"

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
      [&](Vec3 p) {
        return std::min({std::abs(p.x - lo.x), std::abs(p.x - hi.x), std::abs(p.y - lo.y), std::abs(p.y - hi.y)});
      });
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
      [](Vec3 p) {
        return std::min({std::abs(std::hypot(p.x, p.y) - 5.0), std::abs(p.x), std::abs(p.y)});
      });
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
    p.fill_constant_interiors = false;  // every strategy inverts every pixel, as in the table
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
          const bool reference =
              !solver.solve({L.x_of_col(col), L.y_of_row(row), L.z_of_layer(layer)}).preimages.empty();
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

// Fraction 1 of material 0 below z_mm; throws for any sample above it whose y is below y_mm
// (rows run from high y to low, so a layer above z_mm has filled some rows when it throws).
class ThrowsHighUp final : public MaterialFunction {
 public:
  ThrowsHighUp(double z_mm, double y_mm) : MaterialFunction(2), z_mm_(z_mm), y_mm_(y_mm) {}
  std::string_view kind() const noexcept override { return "throws-high-up"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override {
    for (std::size_t s = 0; s < uvw.size(); ++s) {
      if (xyz[s].z > z_mm_ && xyz[s].y < y_mm_) throw Error("material refuses this layer");
      fractions[2 * s] = static_cast<float>(uvw[s].x);
      fractions[2 * s + 1] = 1.0f - static_cast<float>(uvw[s].x);
    }
  }

 private:
  double z_mm_, y_mm_;
};

TEST(Slicer, ALayerDoesNotDependOnTheLayersSlicedBefore) {
  // The slicer reuses its rasters from layer to layer: a twisted column, whose outline moves
  // from layer to layer, sliced in a scrambled order and after a layer that threw half-way,
  // must give every layer the labels and counts a fresh slicer gives it.
  const Volume column = test::twisted_bent_box(8, 6, 5);
  const Box3 box = column.bounds();
  const double z_throw = box.lo.z + 0.8 * (box.hi.z - box.lo.z);
  const double y_throw = 0.5 * (box.lo.y + box.hi.y);
  Cell cell{"column", "/cells/0", column, std::make_shared<ThrowsHighUp>(z_throw, y_throw)};
  const Scene scene = test::scene_with({cell}, 2);
  const Slicer reused(scene, {});
  const SliceLayout& L = reused.layout();
  int high = L.num_layers - 1;
  while (high > 0 && L.z_of_layer(high) > box.hi.z - 0.05) --high;  // a layer through the top
  ASSERT_GT(L.z_of_layer(high), z_throw);
  auto layer_at = [&](double fraction) {  // the last layer below that fraction of the height
    int layer = 0;
    while (layer + 1 < L.num_layers && L.z_of_layer(layer + 1) < box.lo.z + fraction * (box.hi.z - box.lo.z)) ++layer;
    return layer;
  };
  const int layers[] = {layer_at(0.5), 1, layer_at(0.5), layer_at(0.75), 1};
  for (int round = 0; round < 2; ++round) {
    for (int layer : layers) {
      const LayerResult got = reused.slice_layer(layer);
      const Slicer fresh(scene, {});
      const LayerResult want = fresh.slice_layer(layer);
      EXPECT_EQ(got.labels, want.labels) << "layer " << layer;
      EXPECT_EQ(got.stats.pixels_inside, want.stats.pixels_inside) << "layer " << layer;
      EXPECT_GT(got.stats.pixels_inside, 0) << "layer " << layer;
      EXPECT_EQ(got.stats.voxels_per_material, want.stats.voxels_per_material) << "layer " << layer;
    }
    EXPECT_THROW(reused.slice_layer(high), Error);
  }
}

// Gives every sample the same fractions, whatever they are (no fraction policy).
class FixedFractions final : public MaterialFunction {
 public:
  explicit FixedFractions(std::vector<float> f) : MaterialFunction(static_cast<int>(f.size())), f_(std::move(f)) {}
  std::string_view kind() const noexcept override { return "fixed"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>, std::span<float> fractions) const override {
    for (std::size_t s = 0; s < uvw.size(); ++s)
      std::copy(f_.begin(), f_.end(), fractions.begin() + static_cast<std::ptrdiff_t>(s * f_.size()));
  }

 private:
  std::vector<float> f_;
};

TEST(Slicer, FractionsBeyondTheDitheringToleranceAreRefusedNamingThePixel) {
  // The slicer checks the fractions as it writes them into the layer's grid (the dithering
  // does not check the grid again): a material outside the scene's fraction policy is caught.
  const Volume box = box_volume({0, 0, 0}, {4, 3, 1});
  struct Case {
    std::vector<float> f;
    const char* rule;
  };
  for (const Case& c : {Case{{0.7f, 0.7f}, "fractions sum to 1.4"}, Case{{1.5f, 0.0f}, "fraction 1.5 is not finite"},
                        Case{{NAN, 0.5f}, "fraction nan is not finite"}}) {
    const Scene scene = test::scene_with({Cell{"bad", "/cells/0", box, std::make_shared<FixedFractions>(c.f)}}, 2);
    const Slicer slicer(scene, {});
    try {
      (void)slicer.slice_layer(slicer.layout().num_layers / 2);
      ADD_FAILURE() << "no error for " << c.rule;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("material grid: pixel ("), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.rule), std::string::npos) << e.what();
    }
  }
  // Within the tolerance (1e-4 by default) the layer is sliced.
  const Scene scene = test::scene_with(
      {Cell{"ok", "/cells/0", box, std::make_shared<FixedFractions>(std::vector<float>{0.50004f, 0.50004f})}}, 2);
  const Slicer slicer(scene, {});
  EXPECT_GT(slicer.slice_layer(slicer.layout().num_layers / 2).stats.pixels_inside, 0);
}

}  // namespace
}  // namespace trivox
