// The fast Volume evaluator against the general TensorSpline path (the reference), against
// finite differences, and against exact analytic shapes.
#include "trivox/spline/volume.h"

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/limits.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {
namespace {

Vec3 random_param(std::mt19937& rng, const ParamBox& d) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  return {d.lo.x + U(rng) * (d.hi.x - d.lo.x), d.lo.y + U(rng) * (d.hi.y - d.lo.y),
          d.lo.z + U(rng) * (d.hi.z - d.lo.z)};
}

Volume random_rational_volume(std::mt19937& rng) { return Volume(test::random_rational_spline(rng)); }

// Both fast kernels against TensorSpline's general evaluator at random parameters and at
// every breakpoint (where the power form switches pieces and the span convention matters).
void expect_matches_general_path(const Volume& v, std::mt19937& rng) {
  std::vector<Vec3> params;
  for (int s = 0; s < 500; ++s) params.push_back(random_param(rng, v.domain()));
  for (int d = 0; d < 3; ++d)
    for (double knot : v.spline().knots(d).knots()) {
      Vec3 t = random_param(rng, v.domain());
      t[d] = knot;  // outside the domain too: both clamp
      params.push_back(t);
    }
  for (const Vec3& t : params) {
    const double tt[3] = {t.x, t.y, t.z};
    double ref[3], refd[9];
    v.spline().evaluate_with_partials(tt, ref, refd);
    Vec3 p;
    Mat3 J;
    v.evaluate_jacobian(t, p, J);
    const Vec3 q = v.evaluate(t);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(p[c], ref[c], 1e-12) << t.x << ' ' << t.y << ' ' << t.z;
      EXPECT_NEAR(q[c], ref[c], 1e-12) << t.x << ' ' << t.y << ' ' << t.z;
      for (int d = 0; d < 3; ++d)
        EXPECT_NEAR(J.m[static_cast<std::size_t>(c)][static_cast<std::size_t>(d)], refd[d * 3 + c],
                    1e-10 * (1 + std::abs(refd[d * 3 + c])));
    }
    double only[3];
    v.spline().evaluate(tt, only);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(only[c], ref[c], 1e-12);
  }
}

// Mixed orders 2, 3, 4, a repeated interior knot of full multiplicity (a jump) and one of
// multiplicity 2 (a kink in the quadratic direction), non-uniform spacing.
TensorSpline discontinuous_spline(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0), W(0.5, 2.0);
  const KnotVector ku(4, {0, 0, 0, 0, 0.25, 0.25, 0.25, 0.25, 0.7, 1, 1, 1, 1});
  const KnotVector kv(2, {-1, -1, 0.5, 2, 2});
  const KnotVector kw(3, {0, 0, 0, 0.4, 0.4, 3, 3, 3});
  const int n = ku.num_ctrl() * kv.num_ctrl() * kw.num_ctrl();
  std::vector<double> pts, w;
  for (int i = 0; i < n; ++i) {
    pts.insert(pts.end(), {U(rng), U(rng), U(rng)});
    w.push_back(W(rng));
  }
  return TensorSpline({ku, kv, kw}, 3, pts, w);
}

TEST(Volume, FastEvaluatorsMatchGeneralPath) {
  std::mt19937 rng(7);
  const std::vector<TensorSpline> splines = {test::random_rational_spline(rng), discontinuous_spline(rng),
                                             test::twisted_bent_box(3, 2, 1).spline(),
                                             test::annulus_sector(1, 2, 1).spline()};
  VolumeOptions de_boor;
  de_boor.power_form = false;
  for (const TensorSpline& s : splines) {
    const Volume fast(s), reference_kernel(s, de_boor);
    EXPECT_EQ(fast.kernel(), VolumeKernel::kPowerForm);
    EXPECT_EQ(reference_kernel.kernel(), VolumeKernel::kDeBoor);
    expect_matches_general_path(fast, rng);
    expect_matches_general_path(reference_kernel, rng);
  }
}

// The tracer evaluates its guesses (evaluate_many, which interleaves up to four evaluations)
// and its Jacobian steps (evaluate_jacobian_many) in batches: every point's value and
// Jacobian must come out as the single-point evaluators give them, bit for bit, so that the
// tracer's answers do not depend on how many rows it batches. Counts 0 to 9 cover whole
// groups of four and every remainder.
TEST(Volume, EvaluateManyIsBitIdenticalToSinglePoints) {
  std::mt19937 rng(11);
  VolumeOptions de_boor;
  de_boor.power_form = false;
  const std::vector<TensorSpline> splines = {test::random_rational_spline(rng), discontinuous_spline(rng),
                                             test::twisted_bent_box(3, 2, 1).spline()};
  for (const TensorSpline& s : splines)
    for (const Volume& v : {Volume(s), Volume(s, de_boor)})
      for (std::size_t count = 0; count <= 9; ++count) {
        std::vector<Vec3> t(count);
        for (Vec3& p : t) p = random_param(rng, v.domain());
        if (count > 2) t[1][0] = v.spline().knots(0).knots()[4];  // on a breakpoint or an end
        std::vector<Vec3> values(count), values_with_jacobians(count);
        std::vector<Mat3> jacobians(count);
        v.evaluate_many(t, values);
        v.evaluate_jacobian_many(t, values_with_jacobians, jacobians);
        for (std::size_t i = 0; i < count; ++i) {
          const Vec3 q = v.evaluate(t[i]);
          Vec3 qj;
          Mat3 J;
          v.evaluate_jacobian(t[i], qj, J);
          for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(values[i][c], q[c]) << "count " << count << " point " << i;
            EXPECT_EQ(values_with_jacobians[i][c], qj[c]) << "count " << count << " point " << i;
          }
          for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c)
              EXPECT_EQ(jacobians[i].m[r][c], J.m[r][c]) << "count " << count << " point " << i;
        }
      }
}

TEST(Volume, PowerFormFallsBackToDeBoor) {
  std::mt19937 rng(3);
  // Beyond the memory cap.
  VolumeOptions tiny;
  tiny.power_form_max_bytes = 1024;
  const Volume capped(test::twisted_bent_box(3, 2, 1).spline(), tiny);
  EXPECT_EQ(capped.kernel(), VolumeKernel::kDeBoor);
  expect_matches_general_path(capped, rng);
  // Order 5 in one direction.
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const KnotVector k5 = KnotVector::clamped_uniform(5, 7), k2 = KnotVector::clamped_uniform(2, 3);
  std::vector<double> pts;
  for (int i = 0; i < 7 * 3 * 3; ++i) pts.insert(pts.end(), {U(rng), U(rng), U(rng)});
  const Volume quartic(TensorSpline({k5, k2, k2}, 3, pts, {}));
  EXPECT_EQ(quartic.kernel(), VolumeKernel::kDeBoor);
  expect_matches_general_path(quartic, rng);
}

TEST(Volume, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(11);
  const Volume v = random_rational_volume(rng);
  for (int s = 0; s < 200; ++s) {
    const ParamBox& d = v.domain();
    // Stay away from knots so that the central difference sees one polynomial piece.
    Vec3 t = random_param(rng, d);
    Vec3 p;
    Mat3 J;
    v.evaluate_jacobian(t, p, J);
    for (int dir = 0; dir < 3; ++dir) {
      const double h = 1e-6 * (d.hi[dir] - d.lo[dir]);
      Vec3 tp = t, tm = t;
      tp[dir] += h;
      tm[dir] -= h;
      if (tm[dir] < d.lo[dir] || tp[dir] > d.hi[dir]) continue;
      const KnotVector& kv = v.spline().knots(dir);
      if (kv.find_span(tp[dir]) != kv.find_span(tm[dir])) continue;
      const Vec3 fd = (1.0 / (2 * h)) * (v.evaluate(tp) - v.evaluate(tm));
      for (int r = 0; r < 3; ++r)
        EXPECT_NEAR(fd[r], J.m[static_cast<std::size_t>(r)][static_cast<std::size_t>(dir)],
                    1e-5 * (1 + std::abs(fd[r])));
    }
  }
}

TEST(Volume, RationalAnnulusSectorIsExact) {
  const Volume v = test::annulus_sector(1.0, 2.0, 0.5);
  std::mt19937 rng(3);
  for (int s = 0; s < 1000; ++s) {
    const Vec3 t = random_param(rng, v.domain());
    const Vec3 p = v.evaluate(t);
    EXPECT_NEAR(std::hypot(p.x, p.y), 1.0 + t.x, 1e-14);  // radius is linear in u
    EXPECT_NEAR(p.z, 0.5 * t.z, 1e-15);
    EXPECT_GE(p.x, -1e-15);
    EXPECT_GE(p.y, -1e-15);
  }
}

TEST(Volume, PeriodicDirectionCloses) {
  std::mt19937 rng(5);
  const Volume v = random_rational_volume(rng);
  // The unclamped periodic basis repeats with period n = 5 in v: V(u, lo, w) == V(u, hi, w)
  // holds when the pattern is closed, which IRIT's wrapping guarantees up to C^{k-2}.
  for (int s = 0; s < 50; ++s) {
    Vec3 t = random_param(rng, v.domain());
    Vec3 a = t, b = t;
    a.y = v.domain().lo.y;
    b.y = v.domain().hi.y;
    const Vec3 pa = v.evaluate(a), pb = v.evaluate(b);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(pa[c], pb[c], 1e-12);
  }
}

TEST(Volume, SubBoxBoundsAreConservative) {
  const Volume v = test::twisted_bent_box(3, 2, 1);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    ParamBox box;
    for (int d = 0; d < 3; ++d) {
      const double a = U(rng), b = U(rng);
      box.lo[d] = std::min(a, b);
      box.hi[d] = std::max(a, b);
    }
    const Box3 bounds = v.bounds(box);
    for (int s = 0; s < 50; ++s) {
      const Vec3 t = random_param(rng, box);
      EXPECT_TRUE(bounds.contains(v.evaluate(t), 1e-12));
    }
  }
}

TEST(Volume, RejectsNonTrivariates) {
  const TensorSpline curve({KnotVector::bezier(2)}, 3, {0, 0, 0, 1, 1, 1});
  EXPECT_THROW(Volume{curve}, ModelError);
}

TEST(JacobianCheck, ClassifiesOrientation) {
  EXPECT_EQ(check_jacobian(test::twisted_bent_box(3, 2, 1)).classification, JacobianClass::kRightHanded);
  EXPECT_EQ(check_jacobian(test::annulus_sector(1, 2, 1)).classification, JacobianClass::kRightHanded);
  // The solid cylinder sector collapses its u = 0 face onto the axis.
  EXPECT_EQ(check_jacobian(test::cylinder_sector(1, 1)).classification, JacobianClass::kDegenerate);
  // Mirroring x makes it left-handed.
  const Volume mirrored(test::annulus_sector(1, 2, 1).spline().transformed([](std::span<double> p) { p[0] = -p[0]; }));
  EXPECT_EQ(check_jacobian(mirrored).classification, JacobianClass::kLeftHanded);
}

// One trilinear cell with unit weights but for one corner of weight `heaviest` and one of
// `lightest`.
TensorSpline box_weighted(double lightest, double heaviest) {
  const KnotVector kv(2, {0, 0, 1, 1});
  std::vector<double> points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) points.insert(points.end(), {double(i), double(j), double(k)});
  std::vector<double> weights(8, 1.0);
  weights.front() = lightest;
  weights.back() = heaviest;
  return TensorSpline({kv, kv, kv}, 3, points, weights);
}

TEST(Volume, WeightsSpanningUpToTheLimitAreTakenAndBeyondRefusedWithTheirRange) {
  EXPECT_NO_THROW(Volume{box_weighted(1e-6, 1e6)});
  EXPECT_NO_THROW(Volume{box_weighted(1.0, kMaxWeightRatio)});
  for (const auto& [lightest, heaviest] : {std::pair{1e-3, 1e300}, std::pair{1e-3, 1e12}, std::pair{1.0, 1.01e12}}) {
    try {
      (void)box_weighted(lightest, heaviest);
      ADD_FAILURE() << "weights " << lightest << " to " << heaviest << " were taken";
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find("weights range from"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("(control point 7)"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace trivox
