// Evaluate-then-invert round trips, outside points, folds and collapsed faces.
#include "trivox/inverse/invert.h"

#include <atomic>
#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"

namespace trivox {
namespace {

Vec3 random_param(std::mt19937& rng, const ParamBox& d) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  return {d.lo.x + U(rng) * d.size().x, d.lo.y + U(rng) * d.size().y, d.lo.z + U(rng) * d.size().z};
}

struct Fixture {
  const char* name;
  Volume volume;
};

std::vector<Fixture> regular_fixtures() {
  std::vector<Fixture> f;
  f.push_back({"annulus sector (rational)", test::annulus_sector(1.0, 2.0, 0.7)});
  f.push_back({"twisted bent cubic 8x8x8", test::twisted_bent_box(40, 30, 60)});
  f.push_back({"twisted bent quadratic 5x5x5", test::twisted_bent_box(3, 2, 1, 5, 3)});
  // Non-uniform knots (a double knot in u, uneven spans in v and w), other proportions, one
  // only twisted (over a full radian) and one only bent.
  const KnotVector ku(4, {0, 0, 0, 0, 0.15, 0.4, 0.4, 0.8, 1, 1, 1, 1});
  const KnotVector kv(4, {0, 0, 0, 0, 0.3, 0.35, 0.9, 1, 1, 1, 1});
  const KnotVector kw(4, {0, 0, 0, 0, 0.1, 0.2, 0.5, 0.6, 0.95, 1, 1, 1, 1});
  f.push_back({"twisted cubic, non-uniform 8x7x9", test::twisted_bent_volume(ku, kv, kw, {25, 10, 80}, 1.2, 0.0)});
  f.push_back({"bent cubic, non-uniform 7x9x8", test::twisted_bent_volume(kv, kw, ku, {12, 30, 20}, 0.0, 0.45)});
  f.push_back(
      {"left-handed annulus",
       Volume(test::annulus_sector(1.0, 2.0, 0.7).spline().transformed([](std::span<double> p) { p[1] = -p[1]; }))});
  return f;
}

TEST(Inverse, GlobalRoundTripsOnRegularVolumes) {
  for (const Fixture& f : regular_fixtures()) {
    SCOPED_TRACE(f.name);
    const GlobalSolver solver(f.volume);
    std::mt19937 rng(42);
    const Vec3 size = f.volume.domain().size();
    int failures = 0;
    for (int s = 0; s < 10000; ++s) {
      const Vec3 t = random_param(rng, f.volume.domain());
      const Vec3 x = f.volume.evaluate(t);
      const GlobalResult r = solver.solve(x);
      if (r.status != GlobalStatus::kUnique || r.preimages.size() != 1) {
        if (++failures < 5)
          ADD_FAILURE() << "status " << to_string(r.status) << " with " << r.preimages.size()
                        << " preimages at t = " << t.x << " " << t.y << " " << t.z;
        continue;
      }
      const Preimage& p = r.preimages[0];
      EXPECT_LE(p.residual, 1e-8);
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(p.uvw[d], t[d], 1e-6 * size[d]);
    }
    EXPECT_EQ(failures, 0);
  }
}

TEST(Inverse, WarmNewtonRoundTripsFromNeighbourHints) {
  for (const Fixture& f : regular_fixtures()) {
    SCOPED_TRACE(f.name);
    std::mt19937 rng(43);
    const Vec3 size = f.volume.domain().size();
    for (int s = 0; s < 10000; ++s) {
      const Vec3 t = random_param(rng, f.volume.domain());
      // A hint 1% of the domain away, as a neighbouring pixel's solution would be.
      Vec3 hint = t + Vec3{0.01 * size.x, -0.01 * size.y, 0.01 * size.z};
      const InverseResult r = invert(f.volume, f.volume.evaluate(t), hint);
      ASSERT_EQ(r.status, InverseStatus::kConverged) << to_string(r.status);
      EXPECT_LE(r.residual, 1e-8);
      EXPECT_LE(r.iterations, 8);
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(r.uvw[d], t[d], 1e-6 * size[d]);
    }
  }
}

TEST(Inverse, PointsOutsideAreReportedOutside) {
  const Volume v = test::annulus_sector(1.0, 2.0, 0.7);
  const GlobalSolver solver(v);
  // Inside the hole of the annulus, beyond its outer radius, above it, far away.
  for (Vec3 x : {Vec3{0.3, 0.3, 0.3}, Vec3{0.7, 0.7, 0.35}, Vec3{1.5, 1.5, 0.35}, Vec3{1.2, 1.0, 0.8}, Vec3{100, 0, 0},
                 Vec3{-0.5, 1.5, 0.2}}) {
    const GlobalResult r = solver.solve(x);
    EXPECT_EQ(r.status, GlobalStatus::kNone) << x.x << " " << x.y << " " << x.z;
    EXPECT_TRUE(r.preimages.empty());
    // Newton from the middle of the domain cannot converge to a solution that does not exist.
    EXPECT_NE(invert(v, x, v.domain().center()).status, InverseStatus::kConverged);
  }
  // Newton says outside when x lies beyond a face.
  EXPECT_EQ(invert(v, {1.5, 1.5, 0.35}, v.domain().center()).status, InverseStatus::kOutside);
}

// Newton's two other outcomes. On the cylinder sector's axis (u = 0) dV/dv vanishes: a run
// that starts there stops at once, singular.
TEST(Inverse, NewtonStartedOnTheCollapsedAxisIsSingular) {
  const Volume v = test::cylinder_sector(1.0, 1.0);
  const Vec3 x = v.evaluate({0.5, 0.5, 0.5});
  for (Vec3 hint : {Vec3{0.0, 0.5, 0.5}, Vec3{0.0, 0.0, 0.0}, Vec3{0.0, 1.0, 0.9}}) {
    const InverseResult r = invert(v, x, hint);
    EXPECT_EQ(r.status, InverseStatus::kSingular);
    EXPECT_EQ(r.iterations, 1);
    EXPECT_EQ(r.uvw, hint);
    EXPECT_NEAR(r.residual, norm(v.evaluate(hint) - x), 1e-15);
  }
  // Off the axis the same point is found.
  const InverseResult off = invert(v, x, {0.1, 0.5, 0.5});
  EXPECT_EQ(off.status, InverseStatus::kConverged);
  EXPECT_LE(off.residual, 1e-8);
}

// With an iteration budget too small for a far start Newton says so; with the default
// budget the same start converges.
TEST(Inverse, NewtonOutOfIterationsReportsNoConvergence) {
  const Volume v = test::annulus_sector(1.0, 2.0, 0.7);  // rational: every step is evaluated
  const Vec3 x = v.evaluate({0.9, 0.9, 0.9});
  const Vec3 far{0.0, 0.0, 0.0};
  for (int budget : {1, 2}) {
    InverseParams params;
    params.max_iterations = budget;
    const InverseResult r = invert(v, x, far, params);
    EXPECT_EQ(r.status, InverseStatus::kNoConvergence) << budget;
    EXPECT_EQ(r.iterations, budget);
    EXPECT_GT(r.residual, params.residual_tolerance_model);
  }
  const InverseResult full = invert(v, x, far);
  ASSERT_EQ(full.status, InverseStatus::kConverged);
  EXPECT_GT(full.iterations, 2);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(full.uvw[d], 0.9, 1e-8);
}

// A cube folded over itself along x: x(u) = quadratic Bezier with control values 0, 2, 0.5
// rises to 1.25 and comes back, so points with 0.5 < x < 1.125... have two preimages in u.
Volume folded_cube() {
  std::vector<double> pts;
  const double xs[3] = {0.0, 2.0, 0.5};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) pts.insert(pts.end(), {xs[i], static_cast<double>(j), static_cast<double>(k)});
  return Volume(TensorSpline({KnotVector::bezier(3), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts));
}

TEST(Inverse, FoldedVolumeReportsBothPreimages) {
  const Volume v = folded_cube();
  const GlobalSolver solver(v);
  // x(u) = 4u(1-u) + 0.5u^2 = 4u - 3.5u^2; x = 1 at u = (4 -+ sqrt(16 - 14)) / 7.
  const GlobalResult r = solver.solve({1.0, 0.25, 0.5});
  ASSERT_EQ(r.status, GlobalStatus::kMultiple);
  ASSERT_EQ(r.preimages.size(), 2u);
  EXPECT_NEAR(r.preimages[0].uvw.x, (4 - std::sqrt(2.0)) / 7, 1e-9);
  EXPECT_NEAR(r.preimages[1].uvw.x, (4 + std::sqrt(2.0)) / 7, 1e-9);
  EXPECT_LT(r.preimages[0].det * r.preimages[1].det, 0.0);  // opposite orientations
  for (const Preimage& p : r.preimages) {
    EXPECT_NEAR(p.uvw.y, 0.25, 1e-9);
    EXPECT_NEAR(p.uvw.z, 0.5, 1e-9);
  }
  // Below the fold's start only one preimage remains.
  EXPECT_EQ(solver.solve({0.3, 0.5, 0.5}).status, GlobalStatus::kUnique);
}

TEST(Inverse, CollapsedAxisIsHandled) {
  const Volume v = test::cylinder_sector(1.0, 1.0);  // u = 0 collapses onto the z axis
  const GlobalSolver solver(v);
  std::mt19937 rng(44);
  for (int s = 0; s < 2000; ++s) {
    Vec3 t = random_param(rng, v.domain());
    t.x = std::max(t.x, 1e-3);  // off the axis the map is one-to-one
    const GlobalResult r = solver.solve(v.evaluate(t));
    ASSERT_EQ(r.status, GlobalStatus::kUnique);
    EXPECT_NEAR(r.preimages[0].uvw.x, t.x, 1e-6);
    EXPECT_NEAR(r.preimages[0].uvw.y, t.y, 1e-5);
  }
  // On the axis every angle is a preimage: reported as degenerate, never as a fold.
  const GlobalResult axis = solver.solve({0.0, 0.0, 0.5});
  EXPECT_EQ(axis.status, GlobalStatus::kDegenerate);
  ASSERT_FALSE(axis.preimages.empty());
  for (const Preimage& p : axis.preimages) {
    EXPECT_NEAR(p.uvw.x, 0.0, 1e-6);
    EXPECT_NEAR(p.uvw.z, 0.5, 1e-6);
  }
}

TEST(Inverse, BoxBudgetGivesIncompleteNotACrash) {
  const Volume v = test::cylinder_sector(1.0, 1.0);
  const GlobalSolver solver(v);
  GlobalSolveParams tight;
  tight.max_boxes = 3;
  EXPECT_EQ(solver.solve({0.0, 0.0, 0.5}, tight).status, GlobalStatus::kIncomplete);
}

// A raised stop flag ends a solve within 64 boxes with CancelledError; one that stays down
// changes nothing. (A point on the cylinder's collapsed axis takes about 200 boxes.)
TEST(Inverse, StopFlagEndsAGlobalSolve) {
  const Volume v = test::cylinder_sector(1.0, 1.0);
  const GlobalSolver solver(v);
  const Vec3 x{0.0, 0.0, 0.5};
  GlobalSolveParams params;
  const GlobalResult plain = solver.solve(x, params);
  ASSERT_EQ(plain.status, GlobalStatus::kDegenerate);
  ASSERT_GE(plain.boxes_visited, 64) << "the point must need 64 boxes for the flag to be read";
  std::atomic<bool> stop{false};
  params.stop = &stop;
  const GlobalResult down = solver.solve(x, params);
  EXPECT_EQ(down.boxes_visited, plain.boxes_visited);
  ASSERT_EQ(down.preimages.size(), 1u);
  EXPECT_EQ(down.preimages[0].uvw, plain.preimages[0].uvw);
  stop = true;
  EXPECT_THROW(solver.solve(x, params), CancelledError);
}

}  // namespace
}  // namespace trivox

namespace trivox {
namespace {

// The tracing fast path against plain Newton: same solutions, always within tolerance.
TEST(Inverse, NeighbourPredictionAgreesWithNewton) {
  for (const Volume& v : {test::twisted_bent_box(40, 30, 60), test::annulus_sector(1.0, 2.0, 0.7)}) {
    const GlobalSolver solver(v);
    std::mt19937 rng(45);
    std::uniform_real_distribution<double> U(0.05, 0.95);
    for (int s = 0; s < 2000; ++s) {
      const Vec3 t{U(rng), U(rng), U(rng)};
      NeighbourSolution n{t, v.evaluate(t), {}};
      Vec3 p;
      v.evaluate_jacobian(t, p, n.jacobian);
      const Vec3 x = n.x + Vec3{0.0423, -0.0847, 0.0};
      Mat3 J;
      const InverseResult fast = invert_from_neighbour(v, x, n, {}, &J);
      const InverseResult slow = invert(v, x, t);
      ASSERT_EQ(fast.status, slow.status);
      if (fast.status != InverseStatus::kConverged) continue;
      EXPECT_LE(fast.residual, 1e-8);
      EXPECT_LE(norm(v.evaluate(fast.uvw) - x), 1e-8);  // the claim is checked, not trusted
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(fast.uvw[d], slow.uvw[d], 1e-7);
    }
  }
}

}  // namespace
}  // namespace trivox
