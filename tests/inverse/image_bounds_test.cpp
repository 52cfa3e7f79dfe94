// GlobalSolver::image_bounds: the tight box of a volume's image, against analytic extremes
// where the control points overshoot them (a rotated rational arc) and against dense
// sampling (every point inside, for random rational volumes and extreme weights).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

// `s` with every control point turned by `angle` about z (weights kept).
Volume turned(const TensorSpline& s, double angle) {
  std::vector<double> pts(s.points().begin(), s.points().end());
  const double c = std::cos(angle), sn = std::sin(angle);
  for (std::size_t i = 0; i < pts.size(); i += 3) {
    const double x = pts[i], y = pts[i + 1];
    pts[i] = c * x - sn * y;
    pts[i + 1] = sn * x + c * y;
  }
  return Volume(
      TensorSpline(s.all_knots(), 3, std::move(pts), std::vector<double>(s.weights().begin(), s.weights().end())));
}

// Every point of an n^3 grid of the domain lies inside `box`.
void expect_samples_inside(const Volume& v, const Box3& box, int n) {
  const ParamBox& d = v.domain();
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 t{d.lo.x + d.size().x * i / (n - 1), d.lo.y + d.size().y * j / (n - 1),
                     d.lo.z + d.size().z * k / (n - 1)};
        const Vec3 p = v.evaluate(t);
        for (int a = 0; a < 3; ++a) {
          ASSERT_LE(box.lo[a], p[a]) << "axis " << a << " at " << t.x << " " << t.y << " " << t.z;
          ASSERT_GE(box.hi[a], p[a]) << "axis " << a << " at " << t.x << " " << t.y << " " << t.z;
        }
      }
}

TEST(ImageBounds, ARotatedArcIsBoundedByTheCircleNotItsControlPoints) {
  // A quarter annulus (radii 2 and 10) turned by -45 degrees: its outer arc runs from -45 to
  // 45 degrees, so the largest x is 10 at the arc's middle, where the middle control point
  // lies at 10 sqrt(2).
  const Volume v = turned(test::annulus_sector(2.0, 10.0, 1.0).spline(), -M_PI / 4);
  ASSERT_GT(v.bounds().hi.x, 14.0);  // the control points' box
  const double tol = 1e-6;
  const Box3 b = GlobalSolver(v).image_bounds(tol);
  EXPECT_GE(b.hi.x, 10.0);
  EXPECT_LE(b.hi.x, 10.0 + tol);
  EXPECT_NEAR(b.lo.x, 2.0 * std::cos(M_PI / 4), tol);
  EXPECT_NEAR(b.hi.y, 10.0 * std::sin(M_PI / 4), tol);
  EXPECT_NEAR(b.lo.y, -10.0 * std::sin(M_PI / 4), tol);
  EXPECT_NEAR(b.lo.z, 0.0, tol);
  EXPECT_NEAR(b.hi.z, 1.0, tol);
  expect_samples_inside(v, b, 21);
}

TEST(ImageBounds, RandomRationalVolumesHoldEverySample) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 10; ++trial) {
    const Volume v(test::random_rational_spline(rng));
    const Box3 b = GlobalSolver(v).image_bounds(1e-9);
    ASSERT_FALSE(b.empty());
    expect_samples_inside(v, b, 17);
    // Tight: within the control points' box, never wider.
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(b.lo[a], v.bounds().lo[a] - 1e-12);
      EXPECT_LE(b.hi[a], v.bounds().hi[a] + 1e-12);
    }
  }
}

TEST(ImageBounds, WeightsFromOneMillionthToAMillionStayBoundedAndFinish) {
  // A trilinear box of 4 mm whose corners weigh 1e-6 and 1e6 alternately, degree elevated in
  // nothing: the weights only move where the image's points lie along the parameters.
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        pts.insert(pts.end(), {4.0 * i, 4.0 * j, 4.0 * k});
        w.push_back((i + j + k) % 2 == 0 ? 1e-6 : 1e6);
      }
  const Volume v(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts, w));
  const Box3 b = GlobalSolver(v).image_bounds(1e-6);
  expect_samples_inside(v, b, 25);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(b.lo[a], 0.0, 1e-6);  // a corner, which a Bezier net interpolates
    EXPECT_NEAR(b.hi[a], 4.0, 1e-6);
  }
}

}  // namespace
}  // namespace trivox
