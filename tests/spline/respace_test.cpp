// Degree elevation and the other re-expressions keep the geometry; targets that do not
// contain the spline's space are rejected.
#include "trivox/spline/respace.h"

#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/spline/refine.h"

namespace trivox {
namespace {

// Largest coordinate difference between a(t) and b(map(t)) over random t in a's domain.
template <class Map>
double max_deviation(const TensorSpline& a, const TensorSpline& b, Map map, std::mt19937& rng, int samples = 400) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0;
  for (int s = 0; s < samples; ++s) {
    std::array<double, 3> t{}, tb{};
    for (int d = 0; d < a.param_dim(); ++d) t[static_cast<std::size_t>(d)] = a.lo(d) + U(rng) * (a.hi(d) - a.lo(d));
    tb = map(t);
    std::vector<double> pa(static_cast<std::size_t>(a.point_dim())), pb(pa.size());
    a.evaluate(std::span<const double>(t.data(), static_cast<std::size_t>(a.param_dim())), pa);
    b.evaluate(std::span<const double>(tb.data(), static_cast<std::size_t>(b.param_dim())), pb);
    for (std::size_t c = 0; c < pa.size(); ++c) worst = std::max(worst, std::abs(pa[c] - pb[c]));
  }
  return worst;
}

const auto kSame = [](std::array<double, 3> t) { return t; };

TEST(Respace, DegreeElevationKeepsGeometry) {
  std::mt19937 rng(5);
  const TensorSpline box = test::twisted_bent_box(3, 2, 1, 6, 3).spline();
  const double scale = box.control_box().diagonal();
  for (int dir = 0; dir < 3; ++dir)
    for (int times : {1, 2}) {
      const TensorSpline e = elevate_degree(box, dir, times);
      EXPECT_EQ(e.knots(dir).order(), box.knots(dir).order() + times);
      // Every interior knot gains `times` in multiplicity: continuity is kept.
      EXPECT_EQ(e.num_ctrl(dir),
                box.num_ctrl(dir) + times * (1 + static_cast<int>(box.knots(dir).interior_breaks().size())));
      EXPECT_LE(max_deviation(box, e, kSame, rng), 1e-12 * scale);
    }
  // Rational, periodic and unclamped directions: clamped first, then elevated exactly.
  const TensorSpline rat = test::random_rational_spline(rng);
  for (int dir = 0; dir < 3; ++dir) EXPECT_LE(max_deviation(rat, elevate_degree(rat, dir, 2), kSame, rng), 1e-11);
  EXPECT_THROW(elevate_degree(box, 3, 1), ModelError);
  EXPECT_THROW(elevate_degree(box, 0, -1), ModelError);
}

TEST(Respace, FinerSpaceKeepsGeometryAndSmallerIsRejected) {
  std::mt19937 rng(6);
  const TensorSpline box = test::twisted_bent_box(1, 1, 1, 6, 4).spline();
  const KnotVector& kv = box.knots(1);
  std::vector<double> finer(kv.knots().begin(), kv.knots().end());
  finer.insert(finer.begin() + 5, 0.1);
  std::sort(finer.begin(), finer.end());
  const TensorSpline r = respace(box, 1, KnotVector(4, finer));
  EXPECT_EQ(r.num_ctrl(1), box.num_ctrl(1) + 1);
  EXPECT_LE(max_deviation(box, r, kSame, rng), 1e-13);
  EXPECT_THROW(respace(box, 1, KnotVector::bezier(4)), ModelError);                    // drops interior knots
  EXPECT_THROW(respace(box, 1, KnotVector::clamped_uniform(3, 8)), ModelError);        // lower order
  EXPECT_THROW(respace(box, 1, KnotVector::clamped_uniform(4, 8, 0, 2)), ModelError);  // other domain
}

TEST(Respace, InterpolationThroughGrevilleReproducesSplines) {
  const KnotVector kv(4, {0, 0, 0, 0, 0.3, 0.5, 0.5, 1, 1, 1, 1});
  const std::vector<double> ctrl = {1, 4, -2, 0.5, 3, 7, -1};
  const TensorSpline curve({kv}, 1, ctrl);
  const std::vector<double> xi = greville_abscissae(kv);
  std::vector<double> values;
  for (double t : xi) {
    double v;
    curve.evaluate(std::span<const double>(&t, 1), std::span<double>(&v, 1));
    values.push_back(v);
  }
  const std::vector<double> back = interpolate_values(kv, xi, values, 1);
  for (std::size_t i = 0; i < ctrl.size(); ++i) EXPECT_NEAR(back[i], ctrl[i], 1e-12);
  // All parameters in one span break the Schoenberg-Whitney condition.
  const std::vector<double> bad(ctrl.size(), 0.1);
  EXPECT_THROW(interpolate_values(kv, bad, values, 1), ModelError);
}

TEST(Respace, ReparametrizeReverseAndPermuteMoveOnlyParameters) {
  std::mt19937 rng(7);
  const TensorSpline rat = test::random_rational_spline(rng);
  const TensorSpline r = reparametrized(rat, 2, -1.0, 3.0);
  EXPECT_DOUBLE_EQ(r.lo(2), -1.0);
  EXPECT_DOUBLE_EQ(r.hi(2), 3.0);
  const double a = rat.lo(2), b = rat.hi(2);
  EXPECT_LE(max_deviation(
                rat, r,
                [&](std::array<double, 3> t) {
                  t[2] = -1 + 4 * (t[2] - a) / (b - a);
                  return t;
                },
                rng),
            1e-12);
  for (int dir = 0; dir < 3; ++dir) {
    const TensorSpline v = reversed(rat, dir);
    const double lo = rat.lo(dir), hi = rat.hi(dir);
    EXPECT_LE(max_deviation(
                  rat, v,
                  [&](std::array<double, 3> t) {
                    t[static_cast<std::size_t>(dir)] = lo + hi - t[static_cast<std::size_t>(dir)];
                    return t;
                  },
                  rng),
              1e-12);
  }
  const std::array<int, 3> order{2, 0, 1};
  const TensorSpline p = permuted(rat, order);
  EXPECT_LE(max_deviation(
                rat, p,
                [](std::array<double, 3> t) {
                  return std::array<double, 3>{t[2], t[0], t[1]};
                },
                rng),
            1e-12);
}

}  // namespace
}  // namespace trivox
