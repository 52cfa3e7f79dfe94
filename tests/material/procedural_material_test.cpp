// The paper's two procedural materials: the duck's porous tiles against the analytic volume
// of two crossing cylinders, and the chalice's twisting curves against rotated positions.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "material/material_test_util.h"
#include "trivox/error.h"
#include "trivox/material/detail/twisting_curves_material.h"
#include "trivox/material/porous_tiles_material.h"

namespace trivox {
namespace {

using test::eval_one;

constexpr ParamBox kUnit{{0, 0, 0}, {1, 1, 1}};

// Fraction of samples in tile (0,0,0) that are void, on an n^3 grid of voxel centres.
double sampled_void_fraction(const PorousTilesMaterial& f, const ParamBox& tile, int n) {
  std::vector<Vec3> row(static_cast<std::size_t>(n)), xyz(row.size());
  std::vector<float> out(row.size() * static_cast<std::size_t>(f.num_materials()));
  long empty = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Vec3 t{(i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n};
        row[static_cast<std::size_t>(i)] = {tile.lo.x + t.x * (tile.hi.x - tile.lo.x),
                                            tile.lo.y + t.y * (tile.hi.y - tile.lo.y),
                                            tile.lo.z + t.z * (tile.hi.z - tile.lo.z)};
      }
      f.evaluate_row(row, xyz, out);
      for (std::size_t s = 0; s < row.size(); ++s) {
        float sum = 0;
        for (int m = 0; m < f.num_materials(); ++m)
          sum += out[s * static_cast<std::size_t>(f.num_materials()) + static_cast<std::size_t>(m)];
        if (sum == 0.0f) ++empty;
      }
    }
  return static_cast<double>(empty) / (static_cast<double>(n) * n * n);
}

TEST(MaterialPorousTiles, VoidVolumeMatchesTwoCrossingCylinders) {
  for (double r : {0.15, 0.3, 0.45}) {
    PorousTilesParams p;
    p.tiles = {3, 2, 4};
    p.radius = r;
    // A cell on a non-unit domain: tiles are measured in their own unit coordinates.
    const ParamBox cell{{0, 0, 0}, {6, 1, 2}};
    const PorousTilesMaterial f(p, 2, cell);
    // Tile (1, 1, 2): u in [2, 4], v in [0.5, 1], w in [1, 1.5].
    const double sampled = sampled_void_fraction(f, {{2, 0.5, 1}, {4, 1, 1.5}}, 128);
    // Two cylinders of radius r through a unit cube's centre, minus their Steinmetz
    // intersection 16/3 r^3.
    const double analytic = 2 * std::numbers::pi * r * r - 16.0 / 3.0 * r * r * r;
    EXPECT_NEAR(sampled, analytic, 0.01 * analytic) << "r = " << r;
  }
}

TEST(MaterialPorousTiles, TilesAlternateByIndexParity) {
  PorousTilesParams p;
  p.tiles = {2, 2, 2};
  p.radius = 0.2;
  p.materials = {1, 0};
  const PorousTilesMaterial f(p, 2, kUnit);
  // Near a tile's corner, away from the cylinders (which pass through the centre).
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        const Vec3 corner{0.5 * i + 0.05, 0.5 * j + 0.05, 0.5 * k + 0.05};
        const std::vector<float> v = eval_one(f, corner);
        const int expected = (i + j + k) % 2 == 0 ? 1 : 0;
        EXPECT_EQ(v[static_cast<std::size_t>(expected)], 1.0f);
        EXPECT_EQ(v[static_cast<std::size_t>(1 - expected)], 0.0f);
      }
  // The tile's centre is on both cylinders' axes: void.
  EXPECT_EQ(eval_one(f, {0.25, 0.25, 0.25}), (std::vector<float>{0.0f, 0.0f}));
}

TEST(MaterialPorousTiles, CylindersRunAlongTheChosenAxes) {
  PorousTilesParams p;
  p.tiles = {1, 1, 1};
  p.radius = 0.2;
  p.materials = {0, 0};
  p.cylinder_axes = {0, 2};  // along u and along w
  const PorousTilesMaterial f(p, 1, kUnit);
  // Along u through the centre (v = w = 0.5): void for every u.
  EXPECT_EQ(eval_one(f, {0.05, 0.5, 0.5})[0], 0.0f);
  // Along w (u = v = 0.5): void.
  EXPECT_EQ(eval_one(f, {0.5, 0.5, 0.95})[0], 0.0f);
  // Along v there is no cylinder: (0.5, 0.05, 0.5) is 0.45 from the u-axis line in (v, w)
  // and 0.45 from the w-axis line in (u, v).
  EXPECT_EQ(eval_one(f, {0.5, 0.05, 0.5})[0], 1.0f);
}

TEST(MaterialPorousTiles, RejectsBadParameters) {
  PorousTilesParams p;
  p.radius = 0.6;
  EXPECT_THROW(PorousTilesMaterial(p, 2, kUnit), Error);
  p = {};
  p.tiles = {0, 1, 1};
  EXPECT_THROW(PorousTilesMaterial(p, 2, kUnit), Error);
  p = {};
  p.cylinder_axes = {1, 1};
  EXPECT_THROW(PorousTilesMaterial(p, 2, kUnit), Error);
  p = {};
  p.materials = {0, 2};
  EXPECT_THROW(PorousTilesMaterial(p, 2, kUnit), Error);
}

TwistingCurvesParams one_point_params() {
  TwistingCurvesParams p;
  p.points = {{0.8, 0.5, 1}};  // 0.3 from the centre along +u
  p.radius = 0.05;
  p.turns_per_w = 1.0;
  p.background = 0;
  return p;
}

TEST(MaterialTwistingCurves, PointTakesItsColourAndTurnsWithW) {
  const TwistingCurvesMaterial f(one_point_params(), 2, kUnit);
  // w = 0: the point's colour at (u0, v0), background elsewhere.
  EXPECT_EQ(eval_one(f, {0.8, 0.5, 0.0}), (std::vector<float>{0.0f, 1.0f}));
  EXPECT_EQ(eval_one(f, {0.5, 0.8, 0.0}), (std::vector<float>{1.0f, 0.0f}));
  // w = 0.25 with one turn per unit w: a quarter turn counter-clockwise, to (0.5, 0.8).
  EXPECT_EQ(eval_one(f, {0.5, 0.8, 0.25}), (std::vector<float>{0.0f, 1.0f}));
  EXPECT_EQ(eval_one(f, {0.8, 0.5, 0.25}), (std::vector<float>{1.0f, 0.0f}));
  // Just inside and just outside the radius at w = 0.25.
  EXPECT_EQ(eval_one(f, {0.5 + 0.049, 0.8, 0.25})[1], 1.0f);
  EXPECT_EQ(eval_one(f, {0.5 + 0.051, 0.8, 0.25})[1], 0.0f);
  const auto q = f.point_at(0, 0.25);
  EXPECT_NEAR(q[0], 0.5, 1e-12);
  EXPECT_NEAR(q[1], 0.8, 1e-12);
}

TEST(MaterialTwistingCurves, CellDomainIsNormalised) {
  // The same definition on a cell whose w runs over [10, 14]: w = 11 is a quarter of the way.
  const TwistingCurvesMaterial f(one_point_params(), 2, {{0, 0, 10}, {2, 2, 14}});
  EXPECT_EQ(eval_one(f, {1.0, 1.6, 11.0})[1], 1.0f);
}

TEST(MaterialTwistingCurves, ShiftWrapAndNearestPoint) {
  TwistingCurvesParams p;
  p.points = {{0.9, 0.5, 0}, {0.5, 0.5, 1}};
  p.radius = 0.3;  // the two discs overlap around u = 0.7
  p.shift_u_per_w = 0.2;
  p.background = kVoidMaterial;
  const TwistingCurvesMaterial plain(p, 2, kUnit);
  // Nearest wins in the overlap: at w = 0, u = 0.72 is nearer 0.9 than 0.5.
  EXPECT_EQ(eval_one(plain, {0.72, 0.5, 0.0})[0], 1.0f);
  EXPECT_EQ(eval_one(plain, {0.68, 0.5, 0.0})[1], 1.0f);
  // w = 1: the first point shifted to u = 1.1, outside the square; without wrapping
  // u = 0.05 is 1.05 away (void), with wrapping 0.05 away.
  EXPECT_EQ(eval_one(plain, {0.05, 0.5, 1.0}), (std::vector<float>{0.0f, 0.0f}));
  p.wrap_u = true;
  const TwistingCurvesMaterial wrapped(p, 2, kUnit);
  EXPECT_EQ(eval_one(wrapped, {0.05, 0.5, 1.0})[0], 1.0f);
}

TEST(MaterialTwistingCurves, RejectsBadParameters) {
  TwistingCurvesParams p = one_point_params();
  p.radius = 0;
  EXPECT_THROW(TwistingCurvesMaterial(p, 2, kUnit), Error);
  p = one_point_params();
  p.points.clear();
  EXPECT_THROW(TwistingCurvesMaterial(p, 2, kUnit), Error);
  p = one_point_params();
  p.background = 5;
  EXPECT_THROW(TwistingCurvesMaterial(p, 2, kUnit), Error);
}

}  // namespace
}  // namespace trivox
