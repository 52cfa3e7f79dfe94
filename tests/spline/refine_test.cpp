// Knot insertion, splitting, restriction and Bezier extraction leave the geometry unchanged.
#include "trivox/spline/refine.h"

#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

// Max distance between a and b over random parameters of a's domain that also lie in b's.
double max_deviation(const TensorSpline& a, const TensorSpline& b, std::mt19937& rng, int samples = 300) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0;
  for (int s = 0; s < samples; ++s) {
    double t[3];
    for (int d = 0; d < b.param_dim(); ++d) t[d] = b.lo(d) + U(rng) * (b.hi(d) - b.lo(d));
    std::vector<double> pa(static_cast<std::size_t>(a.point_dim())), pb(static_cast<std::size_t>(b.point_dim()));
    a.evaluate(std::span<const double>(t, static_cast<std::size_t>(a.param_dim())), pa);
    b.evaluate(std::span<const double>(t, static_cast<std::size_t>(b.param_dim())), pb);
    for (std::size_t c = 0; c < pa.size(); ++c) worst = std::max(worst, std::abs(pa[c] - pb[c]));
  }
  return worst;
}

TensorSpline periodic_rational(std::mt19937& rng) { return test::random_rational_spline(rng); }

TEST(Refine, KnotInsertionKeepsGeometry) {
  std::mt19937 rng(21);
  const Volume box = test::twisted_bent_box(3, 2, 1);
  const double scale = box.bounds().diagonal();
  for (int dir = 0; dir < 3; ++dir)
    for (double t : {0.1, 0.2, 0.5, 0.77}) {
      const TensorSpline r = insert_knot(box.spline(), dir, t, 2);
      EXPECT_EQ(r.num_ctrl(dir), box.spline().num_ctrl(dir) + 2);
      EXPECT_LE(max_deviation(box.spline(), r, rng), 1e-12 * scale);
    }
  const TensorSpline rat = periodic_rational(rng);
  for (int dir = 0; dir < 3; ++dir) {
    const double t = 0.37 * rat.lo(dir) + 0.63 * rat.hi(dir);
    EXPECT_LE(max_deviation(rat, insert_knot(rat, dir, t, 1), rng), 1e-12 * 4);
  }
  EXPECT_THROW(insert_knot(box.spline(), 0, 1.5), ModelError);
  EXPECT_THROW(insert_knot(box.spline(), 0, 0.2, 5), ModelError);  // multiplicity above order
}

TEST(Refine, ClampingUnwrapsPeriodicAndUnclamped) {
  std::mt19937 rng(22);
  const TensorSpline rat = periodic_rational(rng);
  const TensorSpline c = clamped(rat);
  for (int d = 0; d < 3; ++d) {
    EXPECT_TRUE(c.knots(d).is_clamped());
    EXPECT_DOUBLE_EQ(c.lo(d), rat.lo(d));
    EXPECT_DOUBLE_EQ(c.hi(d), rat.hi(d));
  }
  EXPECT_LE(max_deviation(rat, c, rng), 1e-12 * 4);
}

TEST(Refine, SplitPiecesReproduceTheirHalves) {
  std::mt19937 rng(23);
  const TensorSpline rat = periodic_rational(rng);
  for (int dir = 0; dir < 3; ++dir) {
    const double t = 0.4 * rat.lo(dir) + 0.6 * rat.hi(dir);
    const auto [left, right] = split(rat, dir, t);
    EXPECT_DOUBLE_EQ(left.hi(dir), t);
    EXPECT_DOUBLE_EQ(right.lo(dir), t);
    EXPECT_LE(max_deviation(rat, left, rng), 1e-12 * 4);
    EXPECT_LE(max_deviation(rat, right, rng), 1e-12 * 4);
  }
}

TEST(Refine, RestrictedControlBoxBoundsThePiece) {
  std::mt19937 rng(24);
  const Volume v = test::twisted_bent_box(3, 2, 1);
  const double lo[3] = {0.2, 0.3, 0.1}, hi[3] = {0.45, 0.9, 0.3};
  const TensorSpline piece = restrict_to(v.spline(), lo, hi);
  EXPECT_LE(max_deviation(v.spline(), piece, rng), 1e-12 * 4);
  const Box3 box = piece.control_box();
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int s = 0; s < 500; ++s) {
    const Vec3 t{lo[0] + U(rng) * (hi[0] - lo[0]), lo[1] + U(rng) * (hi[1] - lo[1]), lo[2] + U(rng) * (hi[2] - lo[2])};
    EXPECT_TRUE(box.contains(v.evaluate(t), 1e-12));
  }
  // The piece's control hull is much tighter than the whole volume's.
  EXPECT_LT(box.diagonal(), 0.6 * v.bounds().diagonal());
}

TEST(Refine, BezierPatchesTileTheDomain) {
  std::mt19937 rng(25);
  const Volume v = test::twisted_bent_box(3, 2, 1, 6, 3);  // 4 pieces per direction
  const auto patches = bezier_patches(v.spline());
  ASSERT_EQ(patches.size(), 64u);
  for (const TensorSpline& p : patches) {
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(p.num_ctrl(d), 3);
      EXPECT_TRUE(p.knots(d).interior_breaks().empty());
    }
    EXPECT_LE(max_deviation(v.spline(), p, rng, 50), 1e-12 * 4);
  }
}

}  // namespace
}  // namespace trivox
