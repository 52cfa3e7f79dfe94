// The global solver's exclusion tests are exact: Krawczyk's "no root in this box" is checked
// against a brute-force search, and the separating-plane hint may change the work but never
// the preimages found. Its fast paths give the answers of their plain references: the index
// of the pieces' boxes those of a scan of every box, a polynomial net's division-free hulls
// and bounds the same numbers as dividing by its unit weights.
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "inverse/bezier_net.h"
#include "inverse/box_tree.h"
#include "inverse/newton.h"
#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/spline/refine.h"

namespace trivox {
namespace {

Vec3 lerp(const ParamBox& b, Vec3 t) {
  return {b.lo.x + t.x * b.size().x, b.lo.y + t.y * b.size().y, b.lo.z + t.z * b.size().z};
}

// The Bezier net of `volume` restricted to `box` (by knot insertion at the box's faces).
detail::BezierNet net_on(const Volume& volume, const ParamBox& box) {
  const double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
  const std::vector<TensorSpline> patches = bezier_patches(restrict_to(volume.spline(), lo, hi));
  EXPECT_EQ(patches.size(), 1u);
  const TensorSpline& p = patches.front();
  detail::BezierNet net;
  net.box = box;
  for (int d = 0; d < 3; ++d) net.order[static_cast<std::size_t>(d)] = p.knots(d).order();
  net.h.resize(static_cast<std::size_t>(p.total_ctrl()));
  for (int k = 0; k < p.num_ctrl(2); ++k)
    for (int j = 0; j < p.num_ctrl(1); ++j)
      for (int i = 0; i < p.num_ctrl(0); ++i) {
        const auto q = p.point(i, j, k);
        const double w = p.weight(i, j, k);
        net.at(i, j, k) = {w * q[0], w * q[1], w * q[2], w};
      }
  return net;
}

TEST(Exclusion, KrawczykNoRootMeansNoPointOfTheBoxMapsNearX) {
  // A single-piece quadratic volume (bent and twisted), so that sub-boxes are easy to cut.
  const Volume v = test::twisted_bent_box(3, 2, 1, 3, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.0, 1.0), S(0.02, 0.3);
  int excluded = 0, injective = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 lo{U(rng) * 0.7, U(rng) * 0.7, U(rng) * 0.7};
    const ParamBox box{lo, lo + Vec3{S(rng), S(rng), S(rng)}};
    const detail::BezierNet net = net_on(v, box);
    Mat3 jlo, jhi;
    ASSERT_TRUE(net.jacobian_bounds(jlo, jhi));
    Vec3 c;
    Mat3 Jc;
    v.evaluate_jacobian(box.center(), c, Jc);
    // x near the box's image: the image of a point of a slightly larger box, moved a little.
    // Half the time x is the image of a point just inside or outside the box (the hard case:
    // a root near a face), otherwise that image moved off a little.
    const Vec3 t{U(rng) * 1.2 - 0.1, U(rng) * 1.2 - 0.1, U(rng) * 1.2 - 0.1};
    const double off = trial % 2 ? 0.0 : 0.01;
    const Vec3 x = v.evaluate(lerp(box, t)) + Vec3{off * (U(rng) - 0.5), off * (U(rng) - 0.5), 0.0};
    const double tol = 1e-8;
    const detail::BoxVerdict verdict = detail::krawczyk_verdict(box, jlo, jhi, Jc, c, x, tol);
    if (verdict == detail::BoxVerdict::kInjective) ++injective;
    if (verdict != detail::BoxVerdict::kNoRoot) continue;
    ++excluded;
    // Brute force: Newton restricted to the box from a 4^3 grid of starts, and the closest
    // sample of a 12^3 grid; neither may come within the tolerance of x.
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int d = 0; d < 4; ++d) {
          const InverseResult r =
              detail::newton_in_box(v, x, lerp(box, {(a + 0.5) / 4, (b + 0.5) / 4, (d + 0.5) / 4}), box, {});
          EXPECT_NE(r.status, InverseStatus::kConverged) << "trial " << trial;
        }
    double closest = HUGE_VAL;
    for (int a = 0; a <= 12; ++a)
      for (int b = 0; b <= 12; ++b)
        for (int d = 0; d <= 12; ++d)
          closest = std::min(closest, norm(v.evaluate(lerp(box, {a / 12.0, b / 12.0, d / 12.0})) - x));
    EXPECT_GT(closest, tol);
  }
  // The sample is informative: both verdicts occur.
  EXPECT_GT(excluded, 20);
  EXPECT_GT(injective, 20);
}

TEST(Exclusion, OutwardHintNeverChangesThePreimages) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0), D(-1.0, 1.0);
  const Volume v = test::twisted_bent_box(40, 30, 60);
  const GlobalSolver solver(v);
  int hinted_outside = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Points near a random face, inside or outside by up to 0.05 mm, with the face's normal
    // as the hint (and, every third time, a deliberately wrong direction).
    const int face = trial % 3;
    Vec3 t{U(rng), U(rng), U(rng)};
    t[face] = trial % 2 ? 1.0 : 0.0;
    Vec3 p;
    Mat3 J;
    v.evaluate_jacobian(t, p, J);
    Vec3 n = cross(J.column((face + 1) % 3), J.column((face + 2) % 3));
    if (dot(n, J.column(face)) * (t[face] > 0.5 ? 1 : -1) < 0) n = -1.0 * n;
    n = (1.0 / norm(n)) * n;
    const Vec3 x = p + 0.05 * D(rng) * n;
    const Vec3 hint = trial % 3 == 2 ? Vec3{D(rng), D(rng), D(rng)} : n;
    const GlobalResult plain = solver.solve(x), hinted = solver.solve(x, {}, hint);
    ASSERT_EQ(plain.status, hinted.status) << "trial " << trial;
    ASSERT_EQ(plain.preimages.size(), hinted.preimages.size());
    for (std::size_t i = 0; i < plain.preimages.size(); ++i)
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(plain.preimages[i].uvw[d], hinted.preimages[i].uvw[d], 1e-9);
    if (plain.status == GlobalStatus::kNone) {
      ++hinted_outside;
      // The hint Newton would give for such a point points the same way as the true normal.
      const InverseResult r = invert(v, x, t);
      if (r.status == InverseStatus::kOutside) {
        const auto h = detail::outward_hint(v, x, r.uvw);
        ASSERT_TRUE(h.has_value());
        EXPECT_GT(dot(*h, n), 0.0);
      }
    }
  }
  EXPECT_GT(hinted_outside, 30);
}

TEST(PieceIndex, FindsExactlyTheBoxesAScanFindsInTheSameOrder) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-10.0, 10.0), S(0.0, 3.0);
  for (int count : {0, 1, 3, 4, 5, 17, 300}) {
    std::vector<Box3> boxes;
    for (int i = 0; i < count; ++i) {
      const Vec3 lo{U(rng), U(rng), U(rng)};
      // Some boxes are flat or single points, like the pieces of a collapsed face.
      const Vec3 size = i % 7 == 3 ? Vec3{0, 0, 0} : Vec3{S(rng), i % 5 == 1 ? 0.0 : S(rng), S(rng)};
      boxes.push_back({lo, lo + size});
    }
    if (count == 300)
      for (int i = 0; i < 20; ++i) boxes.push_back(boxes[static_cast<std::size_t>(i)]);  // duplicates
    const detail::BoxTree tree(boxes);
    int hits = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      // Points near box corners too, so that the tolerance decides.
      Vec3 p{U(rng), U(rng), U(rng)};
      if (!boxes.empty() && trial % 3 == 0)
        p = boxes[static_cast<std::size_t>(trial) % boxes.size()].hi + Vec3{1e-3, 0, -1e-3};
      const double tol = trial % 2 ? 0.0 : 2e-3;
      std::vector<int> scan, indexed{-1};  // query appends: keep what was there
      for (std::size_t i = 0; i < boxes.size(); ++i)
        if (boxes[i].contains(p, tol)) scan.push_back(static_cast<int>(i));
      tree.query(p, tol, indexed);
      ASSERT_EQ(indexed.front(), -1);
      ASSERT_EQ(std::vector<int>(indexed.begin() + 1, indexed.end()), scan) << "count " << count << " trial " << trial;
      hits += static_cast<int>(scan.size());
    }
    if (count >= 17) {
      EXPECT_GT(hits, 100) << "the points should hit boxes";
    }
  }
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(PolynomialNet, GivesTheNumbersOfDividingByUnitWeights) {
  const Volume v = test::twisted_bent_box(3, 2, 1, 4, 4);  // one cubic piece
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> U(0.0, 1.0), S(0.05, 0.5), D(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Vec3 lo{U(rng) * 0.5, U(rng) * 0.5, U(rng) * 0.5};
    detail::BezierNet divided = net_on(v, {lo, lo + Vec3{S(rng), S(rng), S(rng)}});
    for (const auto& p : divided.h) ASSERT_EQ(p[3], 1.0);
    detail::BezierNet fast = divided;
    fast.polynomial = true;
    // After a few halvings too: halving must keep the flag and the unit weights.
    for (int level = 0; level < 3; ++level) {
      const Box3 a = divided.bounds(), b = fast.bounds();
      for (int d = 0; d < 3; ++d) ASSERT_TRUE(same_bits(a.lo[d], b.lo[d]) && same_bits(a.hi[d], b.hi[d]));
      const Vec3 dir{D(rng), D(rng), D(rng)};
      ASSERT_TRUE(same_bits(divided.max_along(dir), fast.max_along(dir)));
      const auto ea = divided.extents(), eb = fast.extents();
      for (std::size_t d = 0; d < 3; ++d) ASSERT_TRUE(same_bits(ea[d], eb[d]));
      Mat3 alo, ahi, blo, bhi;
      ASSERT_TRUE(divided.jacobian_bounds(alo, ahi));
      ASSERT_TRUE(fast.jacobian_bounds(blo, bhi));
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c)
          ASSERT_TRUE(same_bits(alo.m[r][c], blo.m[r][c]) && same_bits(ahi.m[r][c], bhi.m[r][c]));
      const int dir_index = trial % 3;
      auto halves_a = divided.halve(dir_index);
      auto halves_b = fast.halve(dir_index);
      ASSERT_TRUE(halves_b[0].polynomial && halves_b[1].polynomial);
      const std::size_t pick = static_cast<std::size_t>(level % 2);
      divided = halves_a[pick];
      fast = halves_b[pick];
      for (const auto& p : fast.h) ASSERT_EQ(p[3], 1.0);
    }
  }
}

// Halving is de Casteljau at the middle: each half must be the net that knot insertion
// gives for that half of the box, in every direction, for orders 2 to 4 (quadratic and cubic
// directions mixed), and halving into nets that held other data must leave none of it.
TEST(BezierNet, HalvesAreTheNetsOfTheHalfBoxes) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> U(0.0, 0.5), S(0.1, 0.5);
  for (const Volume& v : {test::twisted_bent_box(3, 2, 1, 4, 4), test::twisted_bent_box(3, 2, 1, 3, 3),
                          test::twisted_bent_box(3, 2, 1, 2, 2)}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Vec3 lo{U(rng), U(rng), U(rng)};
      const ParamBox box{lo, lo + Vec3{S(rng), S(rng), S(rng)}};
      const detail::BezierNet net = net_on(v, box);
      for (int d = 0; d < 3; ++d) {
        detail::BezierNet left = net_on(v, {Vec3{0.6, 0.6, 0.6}, Vec3{0.9, 0.9, 0.9}}), right = left;
        net.halve_into(d, left, right);
        ParamBox left_box = box, right_box = box;
        left_box.hi[d] = right_box.lo[d] = 0.5 * (box.lo[d] + box.hi[d]);
        const auto halves = net.halve(d);
        int k = 0;
        for (const auto& [half, half_box] : {std::pair{&left, left_box}, std::pair{&right, right_box}}) {
          const detail::BezierNet expected = net_on(v, half_box);
          ASSERT_EQ(half->h.size(), expected.h.size());
          for (int c = 0; c < 3; ++c) {
            EXPECT_DOUBLE_EQ(half->box.lo[c], half_box.lo[c]);
            EXPECT_DOUBLE_EQ(half->box.hi[c], half_box.hi[c]);
          }
          for (std::size_t q = 0; q < expected.h.size(); ++q) {
            for (std::size_t c = 0; c < 4; ++c)
              EXPECT_NEAR(half->h[q][c], expected.h[q][c], 1e-12) << "direction " << d;
            EXPECT_EQ(half->h[q], halves[static_cast<std::size_t>(k)].h[q]);  // halve() is halve_into()
          }
          ++k;
        }
      }
    }
  }
}

TEST(PolynomialNet, JacobianBoundsHoldTheJacobianEverywhereInTheBox) {
  // The hodograph hull bounds every Jacobian of the box: the reference is the evaluator.
  const Volume v = test::twisted_bent_box(3, 2, 1, 4, 4);  // one cubic piece
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> U(0.0, 1.0), S(0.05, 0.5);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 lo{U(rng) * 0.5, U(rng) * 0.5, U(rng) * 0.5};
    const ParamBox box{lo, lo + Vec3{S(rng), S(rng), S(rng)}};
    detail::BezierNet net = net_on(v, box);
    net.polynomial = true;
    Mat3 jlo, jhi;
    ASSERT_TRUE(net.jacobian_bounds(jlo, jhi));
    for (int sample = 0; sample < 50; ++sample) {
      Vec3 p;
      Mat3 J;
      v.evaluate_jacobian(lerp(box, {U(rng), U(rng), U(rng)}), p, J);
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) {
          const double slack = 1e-9 * (1.0 + std::abs(J.m[r][c]));
          EXPECT_GE(J.m[r][c], jlo.m[r][c] - slack);
          EXPECT_LE(J.m[r][c], jhi.m[r][c] + slack);
        }
    }
  }
}

}  // namespace
}  // namespace trivox
