// Properties every material kind shares (a row equals n single samples; bounds contain the
// values), and the fraction policy with its error messages.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "material/material_test_util.h"
#include "trivox/error.h"
#include "trivox/material/checked_material.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/detail/spline_field_material.h"
#include "trivox/material/detail/twisting_curves_material.h"
#include "trivox/material/expression_material.h"
#include "trivox/material/porous_tiles_material.h"

namespace trivox {
namespace {

// A cell domain that is not the unit cube, so every kind's domain map is exercised.
constexpr ParamBox kCell{{0, -1, 2}, {3, 1, 6}};

// A cubic 2-component field with interior knots and random-ish coefficients.
TensorSpline cubic_field(int point_dim) {
  const KnotVector kv(4, {0, 0, 0, 0, 0.3, 0.7, 1, 1, 1, 1});
  std::vector<double> pts;
  const int n = kv.num_ctrl() * kv.num_ctrl() * kv.num_ctrl() * point_dim;
  for (int i = 0; i < n; ++i) pts.push_back(0.5 + 0.45 * std::sin(1.7 * i));
  return TensorSpline({kv, kv, kv}, point_dim, pts);
}

std::vector<std::shared_ptr<const MaterialFunction>> all_kinds() {
  std::vector<std::shared_ptr<const MaterialFunction>> out;
  out.push_back(std::make_shared<ConstantMaterial>(std::vector<float>{0.2f, 0.3f, 0.1f}));
  out.push_back(std::make_shared<SplineFieldMaterial>(cubic_field(2), std::vector<int>{2, 0}, 3, kCell));
  out.push_back(std::make_shared<ScalarGradientMaterial>(
      cubic_field(1), std::vector<GradientStop>{{0.2, {1, 0, 0}}, {0.5, {0, 1, 0}}, {0.8, {0, 0.5f, 0.5f}}}, kCell));
  ExpressionParams e;
  e.expressions = {"u*v", "abs(sin(x)) * w", ""};
  out.push_back(std::make_shared<ExpressionMaterial>(e, kCell));
  PorousTilesParams tiles;
  tiles.tiles = {3, 4, 5};
  tiles.radius = 0.35;
  tiles.materials = {0, 2};
  out.push_back(std::make_shared<PorousTilesMaterial>(tiles, 3, kCell));
  TwistingCurvesParams curves;
  curves.points = {{0.3, 0.3, 0}, {0.7, 0.6, 2}};
  curves.radius = 0.1;
  curves.turns_per_w = 1.5;
  curves.background = 1;
  out.push_back(std::make_shared<TwistingCurvesMaterial>(curves, 3, kCell));
  return out;
}

TEST(MaterialFunction, RowEqualsSingleSamples) {
  const std::vector<Vec3> uvw = test::random_params(kCell, 300, 11);
  const std::vector<Vec3> xyz = test::random_params({{-5, -5, -5}, {5, 5, 5}}, 300, 12);
  for (const auto& f : all_kinds()) {
    const std::vector<float> row = test::eval_row(*f, uvw, xyz);
    const auto m = static_cast<std::size_t>(f->num_materials());
    for (std::size_t s = 0; s < uvw.size(); ++s) {
      const std::vector<float> one = test::eval_one(*f, uvw[s], xyz[s]);
      for (std::size_t j = 0; j < m; ++j) ASSERT_EQ(row[s * m + j], one[j]) << f->kind() << " sample " << s;
    }
  }
}

TEST(MaterialFunction, BoundsContainTheValues) {
  // Sub-boxes of the cell of several sizes; every sample inside must lie within the bounds.
  const std::vector<Vec3> corners = test::random_params(kCell, 40, 21);
  for (const auto& f : all_kinds()) {
    const auto m = static_cast<std::size_t>(f->num_materials());
    for (std::size_t b = 0; b + 1 < corners.size(); b += 2) {
      const double scale = 0.02 + 0.5 * static_cast<double>(b) / static_cast<double>(corners.size());
      ParamBox box;
      for (int d = 0; d < 3; ++d) {
        const double half = scale * (kCell.hi[d] - kCell.lo[d]);
        box.lo[d] = std::max(kCell.lo[d], corners[b][d] - half);
        box.hi[d] = std::min(kCell.hi[d], corners[b][d] + half);
      }
      std::vector<float> lo(m), hi(m);
      f->bounds(box, lo, hi);
      const std::vector<Vec3> uvw = test::random_params(box, 200, static_cast<unsigned>(b));
      const std::vector<Vec3> xyz(uvw.size(), Vec3{1, 2, 3});
      const std::vector<float> row = test::eval_row(*f, uvw, xyz);
      for (std::size_t s = 0; s < uvw.size(); ++s)
        for (std::size_t j = 0; j < m; ++j) {
          ASSERT_GE(row[s * m + j], lo[j] - 1e-6f) << f->kind() << " box " << b << " material " << j;
          ASSERT_LE(row[s * m + j], hi[j] + 1e-6f) << f->kind() << " box " << b << " material " << j;
        }
    }
  }
}

TEST(MaterialFunction, PorousBoundsAreExactAwayFromHoles) {
  PorousTilesParams tiles;
  tiles.tiles = {2, 2, 2};
  tiles.radius = 0.2;
  const PorousTilesMaterial f(tiles, 2, {{0, 0, 0}, {1, 1, 1}});
  std::vector<float> lo(2), hi(2);
  f.bounds({{0.01, 0.01, 0.01}, {0.05, 0.05, 0.05}}, lo, hi);  // a corner of tile (0,0,0)
  EXPECT_EQ(lo, (std::vector<float>{1, 0}));
  EXPECT_EQ(hi, (std::vector<float>{1, 0}));
  f.bounds({{0.24, 0.24, 0.24}, {0.26, 0.26, 0.26}}, lo, hi);  // the holes' crossing
  EXPECT_EQ(hi, (std::vector<float>{0, 0}));
  f.bounds({{0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}}, lo, hi);  // across tiles
  EXPECT_EQ(lo, (std::vector<float>{0, 0}));
  EXPECT_EQ(hi, (std::vector<float>{1, 1}));
}

MaterialSite site() { return {"scene.json", "/cells/2/material", "lid", {"A", "B"}}; }

TEST(MaterialFractionPolicy, ErrorPolicyNamesCellAndParameters) {
  const auto inner = std::make_shared<ConstantMaterial>(std::vector<float>{0.8f, 0.5f});
  const CheckedMaterial f(inner, {SumPolicy::kError, 1e-4}, site());
  std::vector<float> out(2);
  try {
    f.evaluate({0.25, 0.5, 0.75}, {}, out);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), "scene.json");
    EXPECT_EQ(e.where(), "/cells/2/material");
    EXPECT_NE(what.find("cell 'lid'"), std::string::npos) << what;
    EXPECT_NE(what.find("1.3"), std::string::npos) << what;
    EXPECT_NE(what.find("(0.25, 0.5, 0.75)"), std::string::npos) << what;
  }
  const CheckedMaterial negative(std::make_shared<ConstantMaterial>(std::vector<float>{-0.1f, 0.5f}),
                                 {SumPolicy::kError, 1e-4}, site());
  try {
    negative.evaluate({0, 0, 0}, {}, out);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'A'"), std::string::npos) << e.what();
  }
}

TEST(MaterialFractionPolicy, WithinToleranceIsCleanedUp) {
  const CheckedMaterial f(std::make_shared<ConstantMaterial>(std::vector<float>{0.50004f, 0.50004f}),
                          {SumPolicy::kError, 1e-4}, site());
  std::vector<float> out(2);
  f.evaluate({0, 0, 0}, {}, out);
  EXPECT_LE(out[0] + out[1], 1.0f + 1e-6f);
  const CheckedMaterial g(std::make_shared<ConstantMaterial>(std::vector<float>{-0.00005f, 0.5f}),
                          {SumPolicy::kError, 1e-4}, site());
  g.evaluate({0, 0, 0}, {}, out);
  EXPECT_EQ(out, (std::vector<float>{0.0f, 0.5f}));
}

TEST(MaterialFractionPolicy, NormaliseClampsAndScales) {
  const CheckedMaterial f(std::make_shared<ConstantMaterial>(std::vector<float>{-0.5f, 0.9f, 0.6f}),
                          {SumPolicy::kNormalise, 1e-4}, {"s.json", "/cells/0/material", "c", {}});
  std::vector<float> out(3);
  f.evaluate({0, 0, 0}, {}, out);
  EXPECT_EQ(out[0], 0.0f);
  EXPECT_NEAR(out[1], 0.6, 1e-6);
  EXPECT_NEAR(out[2], 0.4, 1e-6);
  // Sums below 1 are left alone (the rest is void).
  const CheckedMaterial g(std::make_shared<ConstantMaterial>(std::vector<float>{0.2f, 0.3f}),
                          {SumPolicy::kNormalise, 1e-4}, site());
  std::vector<float> two(2);
  g.evaluate({0, 0, 0}, {}, two);
  EXPECT_EQ(two, (std::vector<float>{0.2f, 0.3f}));
  std::vector<float> lo(2), hi(2);
  g.bounds({{0, 0, 0}, {1, 1, 1}}, lo, hi);
  EXPECT_EQ(lo, two);
}

TEST(MaterialFractionPolicy, NotFiniteIsAlwaysAnError) {
  ExpressionParams e;
  e.expressions = {"sqrt(-1)"};
  const CheckedMaterial f(std::make_shared<ExpressionMaterial>(e, ParamBox{{0, 0, 0}, {1, 1, 1}}),
                          {SumPolicy::kNormalise, 1e-4}, site());
  std::vector<float> out(1);
  EXPECT_THROW(f.evaluate({0, 0, 0}, {}, out), InputError);
}

TEST(MaterialFractionPolicy, ValidatesTolerance) {
  EXPECT_THROW((FractionPolicy{SumPolicy::kError, -1.0}.validate()), Error);
  EXPECT_THROW((FractionPolicy{SumPolicy::kError, NAN}.validate()), Error);
  EXPECT_THROW(CheckedMaterial(nullptr, {}, site()), Error);
}

}  // namespace
}  // namespace trivox
