// Untangling moves only the interior control points: a folded volume comes out with det J of
// one sign on a fine grid, its faces unchanged; a valid volume is left alone.
#include <bit>
#include <cstdint>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/untangle.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/simd.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/refine.h"

namespace trivox {
namespace {

// A 10 x 10 x 10 mm cube as a tricubic Bezier volume (4 x 4 x 4 control points on a uniform
// grid), with its eight interior control points crossed over: the one that belongs near a
// corner is pushed beyond the opposite one, so det J is negative around the centre.
TensorSpline folded_cube() {
  std::vector<double> pts;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        Vec3 p{10.0 * i / 3, 10.0 * j / 3, 10.0 * k / 3};
        const bool interior = i > 0 && i < 3 && j > 0 && j < 3 && k > 0 && k < 3;
        if (interior) p = Vec3{i == 1 ? 30.0 : -20.0, j == 1 ? 30.0 : -20.0, k == 1 ? 30.0 : -20.0};
        pts.insert(pts.end(), {p.x, p.y, p.z});
      }
  const KnotVector b = KnotVector::bezier(4);
  return TensorSpline({b, b, b}, 3, std::move(pts));
}

Vec3 at(const Volume& v, double u, double w, double t) { return v.evaluate({u, w, t}); }

// The largest distance between the two volumes' points on their six faces.
double face_difference(const Volume& a, const Volume& b) {
  double worst = 0.0;
  const int n = 21;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        Vec3 uvw;
        const int dir = f / 2;
        uvw[dir] = f % 2;
        uvw[dir == 0 ? 1 : 0] = double(i) / (n - 1);
        uvw[dir == 2 ? 1 : 2] = double(j) / (n - 1);
        worst = std::max(worst, norm(at(a, uvw.x, uvw.y, uvw.z) - at(b, uvw.x, uvw.y, uvw.z)));
      }
  return worst;
}

TEST(Untangle, FoldedCubeComesOutWithOneSignAndTheSameFaces) {
  const TensorSpline folded = folded_cube();
  const Volume before(folded);
  ASSERT_EQ(check_jacobian(before, {33}).classification, JacobianClass::kFolded);
  const UntangleResult r = untangle(folded, {});
  EXPECT_GT(r.below_target_before, 0);
  EXPECT_LT(r.min_relative_before, 0.0);
  EXPECT_EQ(r.below_target_after, 0);
  EXPECT_GE(r.min_relative_after, 0.05);
  const Volume after(r.spline);
  for (int n : {7, 33, 50}) {
    const JacobianReport j = check_jacobian(after, {n});
    EXPECT_EQ(j.classification, JacobianClass::kRightHanded) << n << " samples: " << j.negative << " negative";
  }
  EXPECT_LE(face_difference(before, after), 1e-12);
  // Knot insertion only: one knot in the middle of each direction's single span.
  EXPECT_EQ(r.spline.num_ctrl(0), 5);
}

// The reference: F summed from det J of Volume::evaluate_jacobian on the same grid.
double reference_objective(const TensorSpline& s, int samples_per_span, double sigma, double scale, double target) {
  const Volume v(s);
  const int n = samples_per_span + 1;  // a Bezier volume: one span per direction
  double f = 0.0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Vec3 x;
        Mat3 jac;
        v.evaluate_jacobian({double(i) / samples_per_span, double(j) / samples_per_span, double(k) / samples_per_span},
                            x, jac);
        const double r = target - sigma * jac.determinant() / scale;
        if (r > 0) f += r * r;
      }
  return f;
}

TEST(Untangle, ObjectiveAndGradientMatchTheirReferences) {
  const TensorSpline s = folded_cube();
  const double scale = 300.0, target = 0.05;
  for (double sigma : {1.0, -1.0}) {
    std::vector<double> grad;
    const double f = detail::untangle_objective(s, 4, sigma, scale, target, &grad);
    ASSERT_GT(f, 0.0);
    EXPECT_NEAR(f, reference_objective(s, 4, sigma, scale, target), 1e-9 * f);
    // Central differences of the reference, coordinate by coordinate.
    const std::vector<double> pts(s.points().begin(), s.points().end());
    for (std::size_t c = 0; c < pts.size(); c += 5) {
      const double h = 1e-5;
      std::vector<double> p = pts, m = pts;
      p[c] += h;
      m[c] -= h;
      const double fd = (reference_objective(TensorSpline(s.all_knots(), 3, p), 4, sigma, scale, target) -
                         reference_objective(TensorSpline(s.all_knots(), 3, m), 4, sigma, scale, target)) /
                        (2 * h);
      EXPECT_NEAR(grad[c], fd, 1e-5 * (1.0 + std::abs(fd))) << "coordinate " << c << ", sigma " << sigma;
    }
  }
}

// The fast objective (det J of several samples at once, on several threads) against the
// reference (one sample at a time, in the grid's order): the same bits, not just close.
void expect_objective_as_reference(const TensorSpline& s, int samples_per_span, double scale, double target) {
  SCOPED_TRACE(testing::Message() << s.num_ctrl(0) << " x " << s.num_ctrl(1) << " x " << s.num_ctrl(2)
                                  << " control points, " << samples_per_span << " samples per span");
  for (double sigma : {1.0, -1.0}) {
    SCOPED_TRACE(testing::Message() << "sigma " << sigma);
    std::vector<double> grad, grad_ref;
    const double f = detail::untangle_objective(s, samples_per_span, sigma, scale, target, &grad);
    const double f_ref = detail::untangle_objective_reference(s, samples_per_span, sigma, scale, target, &grad_ref);
    ASSERT_GT(f_ref, 0.0) << "the case should have samples below the target";
    EXPECT_EQ(std::bit_cast<std::uint64_t>(f), std::bit_cast<std::uint64_t>(f_ref)) << f << " vs " << f_ref;
    ASSERT_EQ(grad.size(), grad_ref.size());
    std::size_t differ = 0, nonzero = 0;
    for (std::size_t i = 0; i < grad.size(); ++i) {
      differ += std::bit_cast<std::uint64_t>(grad[i]) != std::bit_cast<std::uint64_t>(grad_ref[i]);
      nonzero += grad_ref[i] != 0.0;
    }
    EXPECT_EQ(differ, 0u) << "of " << grad.size() << " coordinates, sigma " << sigma;
    EXPECT_GT(nonzero, 0u);
  }
}

// A folded volume of orders 2, 3 and 4 on uneven knots (every span length different, a
// double knot in w), its interior points scattered: the lane groups of the fast objective
// then hold one to four samples, of spans with different first control points.
TensorSpline scattered_mixed_orders() {
  const KnotVector ku(2, {0, 0, 0.3, 0.35, 1, 1});
  const KnotVector kv(3, {-1, -1, -1, 0.2, 0.9, 2, 2, 2});
  const KnotVector kw(4, {0, 0, 0, 0, 0.5, 0.5, 3, 3, 3, 3});
  const int nu = ku.num_ctrl(), nv = kv.num_ctrl(), nw = kw.num_ctrl();
  std::vector<double> pts;
  std::uint64_t state = 12345;
  auto next = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  };
  for (int k = 0; k < nw; ++k)
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const bool interior = i > 0 && i + 1 < nu && j > 0 && j + 1 < nv && k > 0 && k + 1 < nw;
        const double jitter = interior ? 14.0 : 1.5;
        pts.insert(pts.end(), {7.0 * i + jitter * next(), 5.0 * j + jitter * next(), 3.0 * k + jitter * next()});
      }
  return TensorSpline({ku, kv, kw}, 3, std::move(pts));
}

TEST(Untangle, FastObjectiveIsTheReferenceBitForBit) {
  expect_objective_as_reference(folded_cube(), 4, 300.0, 0.05);
  expect_objective_as_reference(folded_cube(), 7, 300.0, 0.05);
  const TensorSpline mixed = scattered_mixed_orders();
  for (int samples : {1, 2, 3, 5}) expect_objective_as_reference(mixed, samples, 40.0, 0.3);
  expect_objective_as_reference(insert_knot(insert_knot(mixed, 0, 0.7), 2, 1.25), 3, 40.0, 0.3);
}

void expect_untangle_as_reference(const TensorSpline& volume, const UntangleParams& p) {
  const UntangleResult fast = untangle(volume, p);
  const UntangleResult slow = detail::untangle_reference(volume, p);
  EXPECT_EQ(fast.iterations, slow.iterations);
  EXPECT_EQ(fast.below_target_before, slow.below_target_before);
  EXPECT_EQ(fast.below_target_after, slow.below_target_after);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(fast.min_relative_after),
            std::bit_cast<std::uint64_t>(slow.min_relative_after));
  ASSERT_EQ(fast.spline.points().size(), slow.spline.points().size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < fast.spline.points().size(); ++i)
    differ +=
        std::bit_cast<std::uint64_t>(fast.spline.points()[i]) != std::bit_cast<std::uint64_t>(slow.spline.points()[i]);
  EXPECT_EQ(differ, 0u) << "of " << fast.spline.points().size() << " coordinates";
}

TEST(Untangle, FastUntanglingIsTheReferenceBitForBit) {
  expect_untangle_as_reference(folded_cube(), {});
  UntangleParams p;
  p.samples_per_span = 2;
  p.iterations = 60;
  p.target_relative = 0.2;
  expect_untangle_as_reference(scattered_mixed_orders(), p);
  for (int threads : {1, 3}) {
    p.threads = threads;
    expect_untangle_as_reference(scattered_mixed_orders(), p);
  }
}

// The fast dets run on the SIMD target chosen (untangle_kernels.cpp); each lane repeats the
// reference's operations and nothing is fused, so every target gives the reference's volume.
TEST(Untangle, EverySimdTargetGivesTheReferencesVolume) {
  struct BestTargetAfterwards {
    ~BestTargetAfterwards() { use_simd_target("best"); }
  } restore;
  UntangleParams p;
  p.samples_per_span = 2;
  p.iterations = 40;
  p.target_relative = 0.2;
  for (const std::string& target : simd_targets()) {
    SCOPED_TRACE(target);
    use_simd_target(target);
    expect_untangle_as_reference(folded_cube(), {});
    expect_untangle_as_reference(scattered_mixed_orders(), p);
  }
}

// A pyramid: the face u = 0 of a cube collapsed to the origin. det J is 0 on that face
// whatever the interior points do, and there the gradient is exactly 0 too (J's v and w
// columns vanish), so once the other samples meet the target the descent ends at a zero
// gradient. The reference then runs its line search on a NaN direction to the end (40
// evaluations); untangle() stops at once, with the same volume.
TEST(Untangle, StopsAtAZeroGradientWithTheReferencesVolume) {
  std::vector<double> pts;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const double t = i / 3.0;
        pts.insert(pts.end(), {10.0 * t, t * 10.0 * j / 3, t * 10.0 * k / 3});
      }
  const KnotVector b = KnotVector::bezier(4);
  const TensorSpline pyramid({b, b, b}, 3, std::move(pts));
  UntangleParams p;
  p.knots_per_span = 0;
  const UntangleResult fast = untangle(pyramid, p);
  const UntangleResult slow = detail::untangle_reference(pyramid, p);
  EXPECT_LT(fast.iterations, p.iterations);
  EXPECT_GT(fast.below_target_after, 0);  // the apex face
  EXPECT_EQ(fast.evaluations + 40, slow.evaluations);
  expect_untangle_as_reference(pyramid, p);
}

TEST(Untangle, ValidVolumeIsLeftAsItIs) {
  const TensorSpline folded = folded_cube();
  std::vector<double> pts(folded.points().begin(), folded.points().end());
  for (int k = 1; k < 3; ++k)
    for (int j = 1; j < 3; ++j)
      for (int i = 1; i < 3; ++i) {
        const std::size_t c = static_cast<std::size_t>(folded.ctrl_linear(i, j, k));
        pts[3 * c] = 10.0 * i / 3;
        pts[3 * c + 1] = 10.0 * j / 3;
        pts[3 * c + 2] = 10.0 * k / 3;
      }
  const TensorSpline cube(folded.all_knots(), 3, pts);
  UntangleParams p;
  p.knots_per_span = 0;
  const UntangleResult r = untangle(cube, p);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.below_target_before, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(r.spline.points()[i], pts[i]);
}

TEST(Untangle, RejectsWhatItCannotUntangle) {
  const KnotVector b = KnotVector::bezier(2);
  const TensorSpline trilinear({b, b, b}, 3, std::vector<double>(24, 0.0));
  UntangleParams none;
  none.knots_per_span = 0;
  EXPECT_THROW(untangle(trilinear, none), ModelError);  // no interior control points
  const TensorSpline cube = folded_cube();
  const TensorSpline rational(cube.all_knots(), 3, std::vector<double>(cube.points().begin(), cube.points().end()),
                              std::vector<double>(64, 1.0));
  EXPECT_THROW(untangle(rational), ModelError);
  UntangleParams bad;
  bad.knots_per_span = 9;
  EXPECT_THROW(untangle(folded_cube(), bad), ModelError);
}

TEST(Untangle, DuckCoonsVolumeNoLongerFolds) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model duck = read_model(dir / "surfaces" / "duck_brep.xml");
  std::vector<TensorSpline> shell;
  for (const Patch& p : duck.patches) shell.push_back(p.spline);
  const Constructed plain = coons(arrange_cube_faces(shell));
  ASSERT_TRUE(check_jacobian(plain.volume, {33}).classification == JacobianClass::kFolded);
  const UntangleResult r = untangle(plain.volume.spline(), {});
  const Volume after(r.spline);
  for (int n : {7, 33, 65}) {
    const JacobianReport j = check_jacobian(after, {n});
    EXPECT_TRUE(j.classification == JacobianClass::kLeftHanded || j.classification == JacobianClass::kRightHanded)
        << n << " samples: " << j.positive << " positive, " << j.negative << " negative, " << j.zero << " zero";
  }
  EXPECT_LE(face_difference(plain.volume, after), 1e-12);
}

}  // namespace
}  // namespace trivox
