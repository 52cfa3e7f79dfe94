// Constant, spline-field and scalar-gradient materials against hand-computed values.
#include <cmath>

#include <gtest/gtest.h>

#include "material/material_test_util.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/detail/spline_field_material.h"

namespace trivox {
namespace {

using test::eval_one;

// Trilinear field on [0,1]^3 with 2 components; corner (i,j,k) holds a[i][j][k] and b[...].
TensorSpline trilinear_field(const double a[8], const double b[8]) {
  std::vector<double> pts;
  for (int c = 0; c < 8; ++c) pts.insert(pts.end(), {a[c], b[c]});
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 2, pts);
}

constexpr ParamBox kUnit{{0, 0, 0}, {1, 1, 1}};

TEST(MaterialConstant, SameFractionsEverywhere) {
  const ConstantMaterial f({0.25f, 0.5f, 0.0f});
  EXPECT_EQ(f.num_materials(), 3);
  EXPECT_EQ(f.kind(), "constant");
  for (Vec3 p : {Vec3{0, 0, 0}, Vec3{0.3, 0.9, 0.1}, Vec3{5, -2, 7}})
    EXPECT_EQ(eval_one(f, p), (std::vector<float>{0.25f, 0.5f, 0.0f}));
  std::vector<float> lo(3), hi(3);
  f.bounds(kUnit, lo, hi);
  EXPECT_EQ(lo, (std::vector<float>{0.25f, 0.5f, 0.0f}));
  EXPECT_EQ(hi, lo);
}

TEST(MaterialConstant, RejectsNonFiniteAndEmpty) {
  EXPECT_THROW(ConstantMaterial({NAN}), Error);
  EXPECT_THROW(ConstantMaterial({}), Error);
}

TEST(MaterialSplineField, TrilinearCornersAndCentre) {
  // Corner c = i + 2j + 4k (u fastest). a = u (a linear ramp), b = corner-dependent values.
  const double a[8] = {0, 1, 0, 1, 0, 1, 0, 1};
  const double b[8] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.0};
  // Three materials: component 0 -> material 2, component 1 -> material 0; material 1 unused.
  const SplineFieldMaterial f(trilinear_field(a, b), {2, 0}, 3, kUnit);
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{static_cast<double>(c & 1), static_cast<double>((c >> 1) & 1), static_cast<double>((c >> 2) & 1)};
    const std::vector<float> v = eval_one(f, p);
    EXPECT_FLOAT_EQ(v[2], static_cast<float>(a[c])) << "corner " << c;
    EXPECT_FLOAT_EQ(v[0], static_cast<float>(b[c])) << "corner " << c;
    EXPECT_EQ(v[1], 0.0f);
  }
  // At the centre a trilinear interpolant is the mean of its 8 corners.
  const std::vector<float> mid = eval_one(f, {0.5, 0.5, 0.5});
  EXPECT_FLOAT_EQ(mid[2], 0.5f);
  EXPECT_FLOAT_EQ(mid[0], static_cast<float>((0.1 + 0.2 + 0.3 + 0.4 + 0.5 + 0.6 + 0.7 + 0.0) / 8));
  // (0.25, 0.5, 0.5): a = u.
  EXPECT_FLOAT_EQ(eval_one(f, {0.25, 0.5, 0.5})[2], 0.25f);
}

TEST(MaterialSplineField, CellDomainMapsAffinelyOntoFieldDomain) {
  const double a[8] = {0, 1, 0, 1, 0, 1, 0, 1};
  const double b[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  // A cell on [0,13] x [2,4] x [-1,1] driven by a field on [0,1]^3.
  const ParamBox cell{{0, 2, -1}, {13, 4, 1}};
  const SplineFieldMaterial f(trilinear_field(a, b), {0, 1}, 2, cell);
  const std::vector<float> v = eval_one(f, {13.0 * 0.3, 3.0, 0.5});
  EXPECT_NEAR(v[0], 0.3, 1e-6);   // u: 3.9 of [0,13] -> 0.3
  EXPECT_NEAR(v[1], 0.75, 1e-6);  // w: 0.5 of [-1,1] -> 0.75
  // Parameters beyond the cell's domain are clamped.
  EXPECT_NEAR(eval_one(f, {20.0, 3.0, 5.0})[0], 1.0, 1e-6);
}

TEST(MaterialSplineField, RationalFieldAndVoidComponent) {
  // A rational quadratic in u with weights (1, 3, 1) and control values (0, 1, 0): at u = 0.5
  // the value is (0.25*0 + 0.5*3*1 + 0.25*0) / (0.25 + 1.5 + 0.25) = 0.75.
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        pts.insert(pts.end(), {i == 1 ? 1.0 : 0.0, 0.5});
        w.push_back(i == 1 ? 3.0 : 1.0);
      }
  const TensorSpline field({KnotVector::bezier(3), KnotVector::bezier(2), KnotVector::bezier(2)}, 2, pts, w);
  const SplineFieldMaterial f(field, {0, kVoidMaterial}, 1, kUnit);
  EXPECT_NEAR(eval_one(f, {0.5, 0.3, 0.8})[0], 0.75, 1e-6);
}

TEST(MaterialSplineField, RejectsBadComponentMaps) {
  const double a[8] = {0, 1, 0, 1, 0, 1, 0, 1};
  EXPECT_THROW(SplineFieldMaterial(trilinear_field(a, a), {0}, 2, kUnit), Error);     // count
  EXPECT_THROW(SplineFieldMaterial(trilinear_field(a, a), {0, 0}, 2, kUnit), Error);  // twice
  EXPECT_THROW(SplineFieldMaterial(trilinear_field(a, a), {0, 2}, 2, kUnit), Error);  // range
  const TensorSpline surface({KnotVector::bezier(2), KnotVector::bezier(2)}, 1, {0, 1, 0, 1});
  EXPECT_THROW(SplineFieldMaterial(surface, {0}, 1, kUnit), Error);
}

TensorSpline linear_in_w(double s0, double s1) {
  // s(u,v,w) = s0 + (s1 - s0) w on [0,1]^3.
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int c = 0; c < 4; ++c) pts.push_back(k == 0 ? s0 : s1);
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 1, pts);
}

TEST(MaterialScalarGradient, InterpolatesBetweenStopsAndClampsAtTheEnds) {
  // s = w in [0, 1]; stops: 0.2 -> A, 0.6 -> half A half B, 1.0 -> B... with a step at 0.8.
  const ScalarGradientMaterial f(linear_in_w(0.0, 1.0),
                                 {{0.2, {1.0f, 0.0f}}, {0.6, {0.5f, 0.5f}}, {0.8, {0.0f, 0.5f}}, {0.8, {0.0f, 1.0f}}},
                                 kUnit);
  auto at = [&](double w) { return eval_one(f, {0.3, 0.7, w}); };
  EXPECT_EQ(at(0.0), (std::vector<float>{1.0f, 0.0f}));  // below the first stop
  EXPECT_EQ(at(0.2), (std::vector<float>{1.0f, 0.0f}));
  const std::vector<float> q = at(0.4);  // halfway between 0.2 and 0.6
  EXPECT_NEAR(q[0], 0.75, 1e-6);
  EXPECT_NEAR(q[1], 0.25, 1e-6);
  const std::vector<float> r = at(0.7);  // halfway between 0.6 and the first 0.8 stop
  EXPECT_NEAR(r[0], 0.25, 1e-6);
  EXPECT_NEAR(r[1], 0.5, 1e-6);
  EXPECT_EQ(at(0.8), (std::vector<float>{0.0f, 1.0f}));  // the later of equal stops applies
  EXPECT_EQ(at(1.0), (std::vector<float>{0.0f, 1.0f}));
}

TEST(MaterialScalarGradient, RejectsBadStops) {
  EXPECT_THROW(ScalarGradientMaterial(linear_in_w(0, 1), {}, kUnit), Error);
  EXPECT_THROW(ScalarGradientMaterial(linear_in_w(0, 1), {{0.5, {1.0f}}, {0.2, {0.0f}}}, kUnit), Error);
  EXPECT_THROW(ScalarGradientMaterial(linear_in_w(0, 1), {{0.0, {1.0f}}, {1.0, {0.0f, 1.0f}}}, kUnit), Error);
  const double a[8] = {0, 1, 0, 1, 0, 1, 0, 1};
  EXPECT_THROW(ScalarGradientMaterial(trilinear_field(a, a), {{0.0, {1.0f}}}, kUnit), Error);
}

TEST(MaterialScalarGradient, IritScalarFieldSphere16) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model model = read_model(dir / "volumes/irit/sphere16.itd");
  ASSERT_FALSE(model.volume_indices().empty());
  const TensorSpline& field = model.patches[static_cast<std::size_t>(model.volume_indices()[0])].spline;
  ASSERT_EQ(field.point_dim(), 1);
  // The gradient maps the field's own range [min, max of its coefficients] onto A -> B, so
  // each sample's B fraction is (s - min) / (max - min) for the field value s there.
  double lo = 1e300, hi = -1e300;
  for (double c : field.points()) {
    lo = std::min(lo, c);
    hi = std::max(hi, c);
  }
  const ParamBox cell{{0, 0, 0}, {1, 1, 1}};
  const ScalarGradientMaterial f(field, {{lo, {1.0f, 0.0f}}, {hi, {0.0f, 1.0f}}}, cell);
  for (const Vec3 p : test::random_params(cell, 50)) {
    const double t[3] = {p.x * field.hi(0), p.y * field.hi(1), p.z * field.hi(2)};
    double s = 0;
    field.evaluate(t, std::span<double>(&s, 1));
    const std::vector<float> v = eval_one(f, p);
    EXPECT_NEAR(v[1], (s - lo) / (hi - lo), 1e-5);
    EXPECT_NEAR(v[0] + v[1], 1.0, 1e-5);
  }
}

}  // namespace
}  // namespace trivox
