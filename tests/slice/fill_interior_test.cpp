// SliceParams::fill_constant_interiors: a constant-material cell takes the pixels its outline
// decides inside without inverting them, against the reference that inverts every candidate.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

SliceParams with_fill(bool fill) {
  SliceParams p;
  p.fill_constant_interiors = fill;
  return p;
}

struct Comparison {
  std::int64_t inside = 0, traced = 0, traced_reference = 0;
  std::vector<Vec3> differing;  // centres of pixels whose label differs
};

// The same layers sliced with and without the fill.
Comparison compare(const Scene& scene, const std::vector<int>& layers) {
  const Slicer filled(scene, with_fill(true)), reference(scene, with_fill(false));
  const SliceLayout& L = filled.layout();
  Comparison c;
  for (int layer : layers) {
    const LayerResult a = filled.slice_layer(layer), b = reference.slice_layer(layer);
    c.inside += b.stats.pixels_inside;
    c.traced += a.stats.candidates;
    c.traced_reference += b.stats.candidates;
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col)
        if (a.labels.at(col, row) != b.labels.at(col, row))
          c.differing.push_back({L.x_of_col(col), L.y_of_row(row), L.z_of_layer(layer)});
  }
  return c;
}

// A pixel the two may decide differently lies within the residual tolerance of a face: its
// centre has a preimage within the slicer's tolerance, on the boundary of the domain.
void expect_on_a_face(const Volume& v, const std::vector<Vec3>& centres) {
  const GlobalSolver solver(v);
  GlobalSolveParams params;
  params.newton.residual_tolerance_model = SliceParams{}.newton.residual_tolerance_model;
  const ParamBox& d = v.domain();
  for (const Vec3& x : centres) {
    const GlobalResult r = solver.solve(x, params);
    ASSERT_FALSE(r.preimages.empty()) << "pixel at " << x.x << ", " << x.y << ", " << x.z << " is outside";
    const Vec3 u = r.preimages.front().uvw;
    bool on_face = false;
    for (int k = 0; k < 3; ++k)
      on_face = on_face || std::abs(u[k] - d.lo[k]) <= 1e-6 * (d.hi[k] - d.lo[k]) ||
                std::abs(u[k] - d.hi[k]) <= 1e-6 * (d.hi[k] - d.lo[k]);
    EXPECT_TRUE(on_face) << "pixel at " << x.x << ", " << x.y << ", " << x.z << " differs away from the faces";
  }
}

// A 10 x 10 mm plate 1 mm thick whose top is a shallow dish, 0.05 mm deep in the middle:
// near its top the face lies nearly in the layers' planes, where the outline mesh's small
// error across the face is a wide one within the layer.
Volume shallow_dish() {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const double z = k == 0 ? 0.0 : (i == 1 && j == 1 ? 0.9 : (i == 1 || j == 1 ? 0.95 : 1.0));
        pts.insert(pts.end(), {5.0 * i, 5.0 * j, z});
      }
  return Volume(TensorSpline({KnotVector::bezier(3), KnotVector::bezier(3), KnotVector::bezier(2)}, 3, pts));
}

std::vector<int> spread_layers(const Slicer& slicer, int count) {
  std::vector<int> layers;
  const int n = slicer.layout().num_layers;
  for (int k = 0; k < count; ++k) layers.push_back(k * (n - 1) / std::max(1, count - 1));
  return layers;
}

// Volumes of every kind the fill meets: a box, a bent and twisted cubic column, an exact
// rational annulus sector, and a cylinder sector whose u = 0 face collapses onto its axis.
TEST(FillInterior, SameInsidePixelsAsInvertingEveryCandidate) {
  struct Case {
    const char* name;
    Volume volume;
  };
  const std::vector<Case> cases = {
      {"box", test::box_volume({1.03, 0.57, 0.0}, {9.71, 5.2, 3.0})},
      {"twisted column", test::twisted_bent_box(8, 6, 5)},
      {"annulus sector", test::annulus_sector(2.0, 6.0, 1.0)},
      {"cylinder sector", test::cylinder_sector(5.0, 1.0)},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const Scene scene = test::scene_with({test::constant_cell(k.volume, 0, 1)}, 1);
    const Slicer probe(scene, {});
    // The first and last layers lie within the band of the flat bottom and top, where nothing
    // is filled; the middle one is mostly filled.
    const Comparison c = compare(scene, spread_layers(probe, 5));
    EXPECT_GT(c.inside, 10000);
    expect_on_a_face(k.volume, c.differing);
    EXPECT_LE(static_cast<double>(c.differing.size()), 1e-4 * static_cast<double>(c.inside));
    const Comparison middle = compare(scene, {probe.layout().num_layers / 2});
    EXPECT_LT(static_cast<double>(middle.traced), 0.5 * static_cast<double>(middle.traced_reference))
        << middle.traced << " traced against " << middle.traced_reference;
  }
}

// Every layer through the dish's top: a pixel is filled only where no triangle of the
// outline mesh within the band's height of the layer lies near it.
TEST(FillInterior, NearlyFlatFacesAreTracedNotFilled) {
  const Volume dish = shallow_dish();
  const Scene scene = test::scene_with({test::constant_cell(dish, 0, 1)}, 1);
  const Slicer probe(scene, {});
  const SliceLayout& L = probe.layout();
  std::vector<int> layers;
  for (int l = 0; l < L.num_layers; ++l)
    if (L.z_of_layer(l) > 0.9) layers.push_back(l);
  ASSERT_GE(layers.size(), 3u);
  const Comparison c = compare(scene, layers);
  EXPECT_GT(c.inside, 10000);
  expect_on_a_face(dish, c.differing);
  EXPECT_LE(static_cast<double>(c.differing.size()), 1e-4 * static_cast<double>(c.inside));
}

// A material that varies needs every pixel's (u, v, w); so does a trimmed cell, and the
// paper's strategies invert every pixel as the paper does.
TEST(FillInterior, OnlyConstantCellsWithTrivoxsOwnStrategies) {
  const Volume column = test::twisted_bent_box(8, 6, 5);
  {
    const Scene scene = test::scene_with({test::gradient_cell(column)}, 2);
    const Slicer probe(scene, {});
    const Comparison c = compare(scene, {probe.layout().num_layers / 2});
    EXPECT_EQ(c.traced, c.traced_reference);
    EXPECT_TRUE(c.differing.empty());
  }
  {
    const Scene scene = test::scene_with({test::constant_cell(column, 0, 1)}, 1);
    for (TracingStrategy s : {TracingStrategy::kPreviousPoint, TracingStrategy::kFull}) {
      SliceParams a = with_fill(true), b = with_fill(false);
      a.tracing = b.tracing = s;
      const Slicer filled(scene, a), reference(scene, b);
      const int layer = filled.layout().num_layers / 2;
      EXPECT_EQ(filled.slice_layer(layer).stats.candidates, reference.slice_layer(layer).stats.candidates)
          << to_string(s);
    }
  }
}

// The paper's duck (../shared) with one constant material: the real outline mesh, at the J750
// resolution of the paper.
TEST(FillInterior, SharedDuckSameInsidePixels) {
  if (test::shared_data_dir().empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Scene duck = read_scene(std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes" / "duck.json");
  Scene scene = test::scene_with({test::constant_cell(duck.cells.at(0).volume, 0, 1)}, 1);
  scene.printer = duck.printer;
  const Slicer probe(scene, {});
  const Comparison c = compare(scene, spread_layers(probe, 4));
  EXPECT_GT(c.inside, 500000);
  expect_on_a_face(scene.cells[0].volume, c.differing);
  EXPECT_LE(static_cast<double>(c.differing.size()), 1e-5 * static_cast<double>(c.inside));
  EXPECT_LT(static_cast<double>(c.traced), 0.1 * static_cast<double>(c.traced_reference));
}

}  // namespace
}  // namespace trivox
