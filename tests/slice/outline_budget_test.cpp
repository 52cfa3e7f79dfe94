// Outline meshes within their budget: a volume whose faces the refinement cannot bring
// within the tolerance (corner weights 0.01 and 100) stops at the budget, and the slicer's
// wider band, decided by the exact inverse, still gives every pixel the global solver gives.
#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "slice/boundary_mesh.h"
#include "trivox/inverse/invert.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

// A 4 mm trilinear box whose corner weights alternate between `a` and `b`.
Volume weighted_box(double a, double b) {
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        pts.insert(pts.end(), {4.0 * i, 4.0 * j, 4.0 * k});
        w.push_back((i + j + k) % 2 == 0 ? a : b);
      }
  return Volume(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts, w));
}

TEST(OutlineBudget, RefinementStopsAtTheBudgetAndSaysHowCloseItCame) {
  const Volume v = weighted_box(0.01, 100);
  const std::int64_t budget = 20000;
  const detail::BoundaryMesh m = detail::build_boundary_mesh(v, 1e-3, budget);
  EXPECT_LE(static_cast<std::int64_t>(m.mesh.vertex_count()), budget);
  EXPECT_LE(detail::boundary_mesh_vertices(m.samples), budget);
  EXPECT_GT(m.deviation_mm, 1e-3);  // the tolerance was not reached
  // A larger budget comes closer; a box of equal weights (trilinear, flat faces) meets any
  // tolerance at once.
  const detail::BoundaryMesh finer = detail::build_boundary_mesh(v, 1e-3, 10 * budget);
  EXPECT_LT(finer.deviation_mm, m.deviation_mm);
  const detail::BoundaryMesh flat = detail::build_boundary_mesh(weighted_box(1, 1), 1e-9, budget);
  EXPECT_LE(flat.deviation_mm, 1e-9);
  EXPECT_LT(static_cast<std::int64_t>(flat.mesh.vertex_count()), 200);
}

// A quadratic 4 mm box whose face centres bulge out by 1 mm (curved faces), its 27 weights
// alternating between w_even and w_odd.
std::string bulged_box_scene(double w_even, double w_odd) {
  std::string points, weights;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        double p[3] = {2.0 * i, 2.0 * j, 2.0 * k};
        const int idx[3] = {i, j, k};
        // A point in the middle of a face (one index at an end, the other two in the middle).
        for (int a = 0; a < 3; ++a)
          if (idx[a] != 1 && idx[(a + 1) % 3] == 1 && idx[(a + 2) % 3] == 1) p[a] += idx[a] == 0 ? -1.0 : 1.0;
        points += fmt::format("{}[{}, {}, {}]", points.empty() ? "" : ", ", p[0], p[1], p[2]);
        weights += fmt::format("{}{}", weights.empty() ? "" : ", ", (i + j + k) % 2 == 0 ? w_even : w_odd);
      }
  return fmt::format(R"({{"version": 1, "units": "mm", "printer": "j750-hm", "materials": [{{"name": "VeroCyan"}}],
   "cells": [{{"name": "box", "geometry": {{"orders": [3, 3, 3],
     "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1]], "points": [{}], "weights": [{}]}},
     "material": {{"kind": "constant", "fractions": {{"VeroCyan": 1}}}}}}]}})",
                     points, weights);
}

// Every pixel the slicer gives the cell is one the global solver finds a preimage for, and
// the reverse, on two layers.
void expect_the_global_solvers_pixels(const Scene& scene, const SliceParams& sp) {
  const Slicer slicer(scene, sp);
  const SliceLayout& L = slicer.layout();
  const GlobalSolver solver(scene.cells.at(0).volume);
  GlobalSolveParams params;
  params.newton.residual_tolerance_model = 1e-6;
  for (int layer : {L.num_layers / 4, L.num_layers / 2}) {
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    int inside = 0, differ = 0;
    for (int r = 0; r < L.height_px; ++r)
      for (int c = 0; c < L.width_px; ++c) {
        const Vec3 x{L.x_of_col(c), L.y_of_row(r), L.z_of_layer(layer)};
        const bool expected = solver.solve(x, params).status != GlobalStatus::kNone;
        const bool got =
            owner[static_cast<std::size_t>(r) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(c)] >=
            0;
        inside += expected;
        differ += expected != got;
      }
    EXPECT_GT(inside, 1000) << "layer " << layer;
    EXPECT_EQ(differ, 0) << "layer " << layer;
  }
}

TEST(OutlineBudget, ACutShortMeshWidensTheBandAndLosesNoPixel) {
  // A memory limit so small that the cell's outline mesh gets 64 vertices (half the limit
  // over the bytes a vertex takes): its faces then lie far from the curved ones, and the
  // band the exact inverse decides must widen to match.
  const Scene scene = parse_scene(bulged_box_scene(1, 1), "bulged_box.json");
  SliceParams sp;
  sp.memory_limit_bytes = 2 * 64 * detail::kBoundaryMeshBytesPerVertex;
  ASSERT_GT(detail::build_boundary_mesh(scene.cells.at(0).volume, 0.0034, 64).deviation_mm, 0.1);
  expect_the_global_solvers_pixels(scene, sp);
}

TEST(OutlineBudget, WeightsOfOneHundredthAndOneHundredStopAtTheBudgetAndLoseNoPixel) {
  // The faces' parametrization is so uneven that the refinement would have gone on for
  // gigabytes; the slicer's own budget (the cell's size in pixels) stops it.
  const Scene scene = parse_scene(bulged_box_scene(0.01, 100), "weighted_box.json");
  expect_the_global_solvers_pixels(scene, {});
}

}  // namespace
}  // namespace trivox
