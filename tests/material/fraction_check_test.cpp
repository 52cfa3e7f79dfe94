// Fraction rules proved before slicing: the expression trees read what muParser reads, every
// kind's enclosure holds every value the kind computes (against plain sampling), and the
// check proves, breaks or gives up where it should.
#include "trivox/material/fraction_check.h"

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "material/material_test_util.h"
#include "trivox/material/detail/composite_material.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/field_scalar_material.h"
#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/detail/spline_field_material.h"
#include "trivox/material/detail/twisting_curves_material.h"
#include "trivox/material/detail/volume_texture.h"
#include "trivox/material/expression_material.h"
#include "trivox/material/porous_tiles_material.h"

namespace trivox {
namespace {

const ParamBox kCell{{0, 0, 0}, {2, 1, 3}};  // a cell domain other than the unit cube

// A random expression of the documented syntax over u v w x y z, `depth` levels deep.
std::string random_expression(std::mt19937& rng, int depth) {
  const auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  static const char* kLeaves[] = {"u", "v", "w", "x", "y", "z", "0.5", "2", "pi", "3e-1", ".25", "k"};
  if (depth <= 0 || pick(4) == 0) return kLeaves[pick(12)];
  const std::string a = random_expression(rng, depth - 1), b = random_expression(rng, depth - 1);
  switch (pick(14)) {
    case 0: return "(" + a + " + " + b + ")";
    case 1: return a + " - " + b;
    case 2: return a + "*" + b;
    case 3: return "(" + a + ")/(" + b + ")";
    case 4: return a + "^" + std::to_string(pick(4));
    case 5: return "-(" + a + ")^2";
    case 6: return a + " < " + b + " ? " + a + " : " + b;
    case 7: return "(" + a + " >= " + b + " || " + a + " == 0.5) && " + b + " != 1";
    case 8: {
      static const char* kFunctions[] = {"sin", "cos", "tan",  "atan", "sinh", "cosh", "tanh", "asinh",
                                         "exp", "abs", "sign", "rint", "sqrt", "ln",   "log2", "log10"};
      return std::string(kFunctions[pick(16)]) + "(" + a + ")";
    }
    case 9: return "min(" + a + ", " + b + ", 0.3)";
    case 10: return "max(" + a + ", " + b + ")";
    case 11: return "avg(" + a + ", " + b + ") + sum(" + a + ")";
    case 12: return "atan2(" + a + ", " + b + ")";
    default: return "abs(" + a + " - rint(" + a + "))";
  }
}

ExpressionParams params_of(std::vector<std::string> expressions) {
  ExpressionParams p;
  p.expressions = std::move(expressions);
  p.constants = {{"k", 0.75}};
  return p;
}

// Every sample of `f` at random points of random sub-boxes lies in the enclosure of its box
// (fractions and sum, allowing for the rounding to float); returns how many boxes were
// bounded (finite enclosures).
int expect_enclosures_hold(const MaterialFunction& f, const ParamBox& cell, std::mt19937& rng,
                           const std::string& what) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const auto m = static_cast<std::size_t>(f.num_materials());
  int bounded = 0;
  for (int trial = 0; trial < 20; ++trial) {
    ParamBox box;
    for (int d = 0; d < 3; ++d) {
      double a = cell.lo[d] + U(rng) * (cell.hi[d] - cell.lo[d]);
      double b = trial % 3 == 0 ? a + 1e-3 * U(rng) * (cell.hi[d] - cell.lo[d])
                                : cell.lo[d] + U(rng) * (cell.hi[d] - cell.lo[d]);
      box.lo[d] = std::min(a, b);
      box.hi[d] = std::min(std::max(a, b), cell.hi[d]);
    }
    const Box3 xyz{{-3 * U(rng), -1, 2}, {U(rng), 4 * U(rng), 2.5}};
    const FractionEnclosure e = f.enclose(box, xyz);
    EXPECT_EQ(e.fractions.size(), m);
    if (!e.finite || e.fractions.size() != m) continue;
    ++bounded;
    const std::vector<Vec3> uvw = test::random_params(box, 64, static_cast<unsigned>(rng()));
    std::vector<Vec3> positions = test::random_params(ParamBox{xyz.lo, xyz.hi}, 64, static_cast<unsigned>(rng()));
    const std::vector<float> values = test::eval_row(f, uvw, positions);
    for (std::size_t s = 0; s < uvw.size(); ++s) {
      double sum = 0.0;
      for (std::size_t j = 0; j < m; ++j) {
        const double v = values[s * m + j];
        const double slack = 1e-6 * std::max(1.0, std::abs(v));
        EXPECT_TRUE(std::isfinite(v)) << what << ": a finite enclosure for a value " << v;
        EXPECT_GE(v, e.fractions[j].lo - slack)
            << what << " fraction " << j << " at " << uvw[s].x << ", " << uvw[s].y << ", " << uvw[s].z;
        EXPECT_LE(v, e.fractions[j].hi + slack) << what << " fraction " << j;
        sum += v;
      }
      const double slack = 1e-6 * std::max(1.0, std::abs(sum));
      EXPECT_GE(sum, e.sum.lo - slack) << what;
      EXPECT_LE(sum, e.sum.hi + slack) << what;
    }
  }
  return bounded;
}

// The parser and muParser agree on every expression of the documented syntax: the material
// trusts its trees for all of them.
TEST(FractionCheck, ExpressionTreesReadWhatMuParserReads) {
  std::mt19937 rng(5);
  for (int i = 0; i < 400; ++i) {
    const std::string text = random_expression(rng, 4);
    SCOPED_TRACE(text);
    const ExpressionMaterial f(params_of({text}), kCell);
    EXPECT_TRUE(f.boundable());
  }
  for (const char* text : {"2^3^2", "-2^2 + u", "2^-u", "1 < 2 < u", "u ? 2 : 0 ? 4 : 5", "-u*-v", "2*-u^2",
                           "rint(2.5 * u)", "sign(u - 0.5)", "u < 0.5 || v > 0.5 && w", "_pi * _e * pi"}) {
    const ExpressionMaterial f(params_of({text}), kCell);
    EXPECT_TRUE(f.boundable()) << text;
  }
}

TEST(FractionCheck, ExpressionEnclosuresHoldEverySample) {
  std::mt19937 rng(11);
  int bounded = 0;
  for (int i = 0; i < 120; ++i) {
    const std::vector<std::string> texts = {random_expression(rng, 3), random_expression(rng, 3)};
    const ExpressionMaterial f(params_of(texts), kCell);
    bounded += expect_enclosures_hold(f, kCell, rng, texts[0] + " | " + texts[1]);
  }
  EXPECT_GT(bounded, 400);  // most are bounded: the test is not vacuous
}

// The example of the first hour: 1 - u and u sum to exactly 1 over any box (the mean-value
// form of the sum: its gradient is 0), where the intervals alone give 2.
TEST(FractionCheck, ComplementaryExpressionsSumToExactlyOne) {
  const ExpressionMaterial f(params_of({"1 - u", "u"}), kCell);
  const FractionEnclosure e = f.enclose(kCell, {{0, 0, 0}, {1, 1, 1}});
  ASSERT_TRUE(e.finite);
  EXPECT_NEAR(e.sum.lo, 1.0, 1e-12);
  EXPECT_NEAR(e.sum.hi, 1.0, 1e-12);
  const ExpressionMaterial g(params_of({"0.2 + x / 40 - 0.3 * w", "0.8 - x / 40 + 0.3 * w"}), kCell);
  EXPECT_NEAR(g.enclose(kCell, {{-10, 0, 0}, {10, 1, 1}}).sum.hi, 1.0, 1e-12);
  // Terms that cancel only to first order need smaller boxes: the check splits them.
  const ExpressionMaterial h(params_of({"0.5 + 0.5*sin(x)", "0.5 - 0.5*sin(x)"}), kCell);
  EXPECT_GT(h.enclose(kCell, {{-10, 0, 0}, {10, 1, 1}}).sum.hi, 1.5);
  // Constants are exact.
  const ConstantMaterial c({0.25f, 0.5f});
  const FractionEnclosure ce = c.enclose(kCell, {});
  EXPECT_NEAR(ce.sum.lo, 0.75, 1e-12);
  EXPECT_NEAR(ce.sum.hi, 0.75, 1e-12);
}

TEST(FractionCheck, EveryKindsEnclosureHoldsEverySample) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::pair<std::string, std::shared_ptr<const MaterialFunction>>> kinds;
  // A quadratic field of three components on its own domain.
  std::vector<double> points;
  for (int i = 0; i < 3 * 3 * 2 * 3; ++i) points.push_back(U(rng) * 0.5);
  const TensorSpline field({KnotVector::bezier(3), KnotVector::bezier(3), KnotVector::bezier(2)}, 3, points);
  kinds.emplace_back("spline_field",
                     std::make_shared<SplineFieldMaterial>(field, std::vector<int>{0, kVoidMaterial, 1}, 3, kCell));
  std::vector<double> scalar;
  for (int i = 0; i < 3 * 3 * 2; ++i) scalar.push_back(U(rng));
  const TensorSpline scalar_field({KnotVector::bezier(3), KnotVector::bezier(3), KnotVector::bezier(2)}, 1, scalar);
  const std::vector<GradientStop> stops = {
      {0.1, {1, 0, 0}}, {0.4, {0, 0.7, 0.3}}, {0.4, {0, 0, 1}}, {0.9, {0.2, 0.2, 0.2}}};
  kinds.emplace_back("scalar_gradient", std::make_shared<ScalarGradientMaterial>(scalar_field, stops, kCell));
  const auto expr = [&](std::vector<std::string> t) {
    return std::make_shared<ExpressionMaterial>(params_of(std::move(t)), kCell);
  };
  const auto a = expr({"u", "1 - u - 0.5*v", "0.5*v*w"}), b = expr({"0.2", "sin(x)^2", "w*0.3"});
  const auto weight = expr({"2*w - 0.5"});
  kinds.emplace_back("blend", std::make_shared<BlendMaterial>(a, b, weight));
  kinds.emplace_back("threshold", std::make_shared<ThresholdMaterial>(expr({"u + v"}), 0.8, a, b));
  kinds.emplace_back("select", std::make_shared<SelectMaterial>(
                                   std::vector<SelectRegion>{{{{0.2, 0.2, 0.2}, {0.6, 0.9, 0.5}}, b}}, a, kCell));
  kinds.emplace_back("void_mask", std::make_shared<VoidMaskMaterial>(a, expr({"x / 3"})));
  kinds.emplace_back("transfer", std::make_shared<TransferMaterial>(expr({"u * w + y / 4"}), stops));
  kinds.emplace_back("field_scalar", std::make_shared<FieldScalarMaterial>(field, FieldScalarChoice{1, false}, kCell));
  kinds.emplace_back("field_magnitude",
                     std::make_shared<FieldScalarMaterial>(field, FieldScalarChoice{0, true}, kCell));
  PorousTilesParams porous;
  porous.tiles = {3, 2, 4};
  porous.radius = 0.3;
  kinds.emplace_back("porous_tiles", std::make_shared<PorousTilesMaterial>(porous, 3, kCell));
  TwistingCurvesParams curves;
  curves.points = {{0.7, 0.5, 0}, {0.3, 0.5, 2}};
  curves.radius = 0.15;
  curves.turns_per_w = 1.0;
  curves.background = 1;
  kinds.emplace_back("twisting_curves", std::make_shared<TwistingCurvesMaterial>(curves, 3, kCell));
  auto image = std::make_shared<VolumeImage>();
  image->nx = 3;
  image->ny = 2;
  image->nz = 2;
  image->channels = 2;
  for (int i = 0; i < 3 * 2 * 2 * 2; ++i) image->values.push_back(static_cast<float>(U(rng) * 0.5));
  TextureSampling sampling;
  sampling.wrap = {TextureWrap::kRepeat, TextureWrap::kMirror, TextureWrap::kClamp};
  sampling.repeats = {2, 1.5, 1};
  kinds.emplace_back(
      "texture", std::make_shared<TextureMaterial>(VolumeTexture(image, sampling), std::vector<int>{2, 0}, 3, kCell));
  for (const auto& [name, f] : kinds) {
    SCOPED_TRACE(name);
    EXPECT_GT(expect_enclosures_hold(*f, kCell, rng, name), 10);
  }
}

// A box 40 x 10 x 5 mm on [0, 1]^3: where the positions the expressions read come from.
TensorSpline bar() {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {40.0 * i, 10.0 * j, 5.0 * k});
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts);
}

FractionCheck check(std::vector<std::string> fractions, FractionPolicy policy = {}, int max_boxes = 20000) {
  const ExpressionMaterial f(params_of(std::move(fractions)), {{0, 0, 0}, {1, 1, 1}});
  FractionCheckParams params;
  params.max_boxes = max_boxes;
  return check_fractions(f, policy, bar(), {"A", "B"}, params);
}

TEST(FractionCheck, ProvesBreaksOrCannotProve) {
  // Proved: complements, a square and its complement (after splitting), a constant.
  for (const auto& pair : std::vector<std::vector<std::string>>{{"1 - u", "u"},
                                                                {"u*u", "1 - u*u"},
                                                                {"0.5*w", "0.25"},
                                                                {"x / 40", "1 - x / 40"},
                                                                {"0.5 + 0.5*sin(x / 8)", "0.5 - 0.5*sin(x / 8)"}}) {
    const FractionCheck c = check(pair);
    EXPECT_EQ(c.outcome, FractionCheckOutcome::kProved) << pair[0] << ", " << pair[1] << ": " << c.reason;
    EXPECT_LE(c.sum_bound, 1.0001);
  }
  // Broken only in a thin band (the first-hour scene): found, with a point where the material
  // really sums above 1.
  const FractionCheck band = check({"u + (abs(w - 0.37) < 0.002 ? 0.5 : 0)", "1 - u"});
  ASSERT_EQ(band.outcome, FractionCheckOutcome::kBroken);
  EXPECT_NEAR(band.uvw.z, 0.37, 0.002);
  EXPECT_NE(band.rule.find("sum to 1.5"), std::string::npos) << band.rule;
  EXPECT_NEAR(band.xyz.x, 40 * band.uvw.x, 1e-9);
  // A negative fraction, a value that is not a number.
  EXPECT_EQ(check({"u - 0.01", "1 - u"}).outcome, FractionCheckOutcome::kBroken);
  const FractionCheck nan = check({"sqrt(u - 0.5)", "0"});
  ASSERT_EQ(nan.outcome, FractionCheckOutcome::kBroken);
  EXPECT_NE(nan.rule.find("not a finite number"), std::string::npos) << nan.rule;
  // Within the tolerance: proved; a sum exactly at 1 + 2e-4 with the tolerance 1e-4: broken.
  EXPECT_EQ(check({"u + 5e-5", "1 - u"}).outcome, FractionCheckOutcome::kProved);
  EXPECT_EQ(check({"u + 2e-4", "1 - u"}).outcome, FractionCheckOutcome::kBroken);
  // sin^2 + cos^2 = 1, but intervals cannot see it over 40 mm of x: cannot prove, not "ok".
  const FractionCheck trig = check({"sin(x)^2", "cos(x)^2"}, {}, 3000);
  EXPECT_EQ(trig.outcome, FractionCheckOutcome::kUnproved);
  EXPECT_NE(trig.reason.find("may reach"), std::string::npos) << trig.reason;
  // Under "normalise" sums above 1 are no error; values that are not numbers still are.
  FractionPolicy normalise;
  normalise.policy = SumPolicy::kNormalise;
  EXPECT_EQ(check({"u + 0.5", "1"}, normalise).outcome, FractionCheckOutcome::kProved);
  EXPECT_EQ(check({"ln(u - 0.5)", "1"}, normalise).outcome, FractionCheckOutcome::kBroken);
}

// Stripes and helices written with the distance to the nearest integer, and a pattern with
// its complement (the paper's teapot spout): proved, case by case on their comparisons.
TEST(FractionCheck, PatternAndComplementAreProved) {
  const std::string a = "abs(u - 1.5 * v - rint(u - 1.5 * v)) < 0.06";
  const std::string b = "abs(u + 0.5 - 1.5 * v - rint(u + 0.5 - 1.5 * v)) < 0.06";
  const ExpressionMaterial f(params_of({a + " ? 1 : 0", b + " ? 1 : 0", a + " || " + b + " ? 0 : 1"}),
                             {{0, 0, 0}, {1, 1, 1}});
  const FractionCheck c = check_fractions(f, {}, bar(), {"A", "B", "C"});
  EXPECT_EQ(c.outcome, FractionCheckOutcome::kProved) << c.reason;
  // Widen one stripe so that they overlap: broken.
  const ExpressionMaterial g(params_of({a + " ? 1 : 0", "abs(u - 1.5 * v - rint(u - 1.5 * v)) < 0.1 ? 1 : 0", "0"}),
                             {{0, 0, 0}, {1, 1, 1}});
  EXPECT_EQ(check_fractions(g, {}, bar(), {"A", "B", "C"}).outcome, FractionCheckOutcome::kBroken);
}

}  // namespace
}  // namespace trivox
