// Second-derivative bounds of polynomial volumes, and the Newton-step certificate built on
// them (invert_from_neighbour's one-evaluation path).
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

// d^2 V / dt_i dt_j by central differences of the Jacobian: the reference the bounds are
// held against (error O(h^2), far below the slack allowed).
double second_derivative_norm(const Volume& v, Vec3 t, int i, int j, double h) {
  Vec3 a = t, b = t, p;
  a[j] -= h;
  b[j] += h;
  Mat3 Ja, Jb;
  v.evaluate_jacobian(a, p, Ja);
  v.evaluate_jacobian(b, p, Jb);
  return norm((1.0 / (2 * h)) * (Jb.column(i) - Ja.column(i)));
}

// A biquadratic-in-everything Bezier volume with V = (u^2, v w, u + w): its second
// derivatives are constant, so the bounds must be exactly |V_uu| = 2, |V_vw| = 1, 0 else.
Volume quadratic_bezier() {
  const KnotVector kv = KnotVector::clamped_uniform(3, 3);
  const double lin[3] = {0.0, 0.5, 1.0}, sq[3] = {0.0, 0.0, 1.0};
  std::vector<double> pts;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        pts.push_back(sq[i]);
        pts.push_back(lin[j] * lin[k]);
        pts.push_back(lin[i] + lin[k]);
      }
  return Volume(TensorSpline({kv, kv, kv}, 3, pts));
}

TEST(SecondDerivativeBounds, ExactForConstantSecondDerivatives) {
  const Volume v = quadratic_bezier();
  ASSERT_TRUE(v.second_derivative_bounds().has_value());
  const Mat3& M = *v.second_derivative_bounds();
  const double expect[3][3] = {{2, 0, 0}, {0, 0, 1}, {0, 1, 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(M.m[i][j], expect[i][j], 1e-12) << i << "," << j;
}

TEST(SecondDerivativeBounds, BoundEverySampledSecondDerivative) {
  std::mt19937 rng(7);
  std::vector<Volume> volumes{test::twisted_bent_box(40, 30, 60), test::twisted_bent_box(3, 2, 1, 5, 3)};
  // Unclamped, periodic and clamped knot vectors, weights dropped: a polynomial volume.
  for (int r = 0; r < 3; ++r) {
    const TensorSpline s = test::random_rational_spline(rng);
    volumes.emplace_back(TensorSpline(s.all_knots(), 3, std::vector<double>(s.points().begin(), s.points().end())));
  }
  for (const Volume& v : volumes) {
    ASSERT_TRUE(v.second_derivative_bounds().has_value());
    const Mat3& M = *v.second_derivative_bounds();
    const ParamBox& d = v.domain();
    const double h = 1e-5 * max_abs(d.size());
    std::uniform_real_distribution<double> U(0.0, 1.0);
    double tightest = 0;  // largest sampled / bound ratio: the bound must not be vacuous
    for (int s = 0; s < 3000; ++s) {
      Vec3 t;
      for (int c = 0; c < 3; ++c) t[c] = d.lo[c] + 2 * h + U(rng) * (d.size()[c] - 4 * h);
      // Central differences across a knot would straddle a jump of the second derivative.
      bool near_knot = false;
      for (int c = 0; c < 3; ++c)
        for (double k : v.spline().knots(c).knots()) near_knot = near_knot || std::abs(t[c] - k) < 3 * h;
      if (near_knot) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double sampled = second_derivative_norm(v, t, i, j, h);
          EXPECT_LE(sampled, M.m[i][j] * (1 + 1e-6) + 1e-6 * (1 + M.m[i][j])) << i << "," << j;
          if (M.m[i][j] > 0) tightest = std::max(tightest, sampled / M.m[i][j]);
        }
    }
    EXPECT_GT(tightest, 0.2);
  }
}

TEST(SecondDerivativeBounds, RationalVolumesHaveNone) {
  EXPECT_FALSE(test::annulus_sector(1.0, 2.0, 0.7).second_derivative_bounds().has_value());
}

// Every step the certificate accepts really meets the tolerance, and the bound it reports is
// at least the true residual. Offsets from a pixel to 2 mm exercise both the certified path
// and the evaluated one.
TEST(SecondDerivativeBounds, CertifiedStepsMeetTheTolerance) {
  const Volume v = test::twisted_bent_box(40, 30, 60);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.05, 0.95), D(-1.0, 1.0);
  const double offsets[] = {0.02, 0.04, 0.2, 2.0};
  int certified = 0, evaluated = 0;
  for (const InverseParams params : {InverseParams{}, InverseParams{1e-6, 30, 1e-9}})
    for (double offset : offsets)
      for (int s = 0; s < 1000; ++s) {
        const Vec3 t{U(rng), U(rng), U(rng)};
        NeighbourSolution n{t, v.evaluate(t), {}};
        Vec3 p;
        v.evaluate_jacobian(t, p, n.jacobian);
        const Vec3 x = n.x + offset * Vec3{D(rng), D(rng), D(rng)};
        const InverseResult r = invert_from_neighbour(v, x, n, params);
        if (r.status != InverseStatus::kConverged) continue;
        const double truth = norm(v.evaluate(r.uvw) - x);
        EXPECT_LE(truth, params.residual_tolerance_model);
        EXPECT_LE(r.residual, params.residual_tolerance_model);
        // Up to the rounding of the coordinates themselves: an evaluated residual comes from
        // the value-and-Jacobian kernel, `truth` from the value kernel, and the two may round
        // the point differently by a few ulps of its coordinates (they do under the
        // sanitizers' build, where the compiler contracts differently).
        const double rounding = 64 * std::numeric_limits<double>::epsilon() * norm(x);
        EXPECT_GE(r.residual, truth * (1 - 1e-9) - rounding) << "the reported residual must bound the true one";
        (r.iterations == 1 ? certified : evaluated) += 1;
      }
  EXPECT_GT(certified, 1000);
  EXPECT_GT(evaluated, 100);
}

}  // namespace
}  // namespace trivox
