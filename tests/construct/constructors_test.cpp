// The volume constructors reproduce their analytic definitions: extrusion and ruled volumes,
// exact cylinders and tori of revolution, Coons volumes that interpolate their faces, thick
// shells of exact offsets, sweeps through their stations; folds are reported with where.
#include <random>

#include <gtest/gtest.h>

#include "construct/construct_fixtures.h"
#include "support/test_support.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/extrude.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/shell.h"
#include "trivox/construct/sweep.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox {
namespace {

using test::eval3;

std::array<double, 3> random_params(const TensorSpline& s, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::array<double, 3> t{};
  for (int d = 0; d < s.param_dim(); ++d) t[static_cast<std::size_t>(d)] = s.lo(d) + U(rng) * (s.hi(d) - s.lo(d));
  return t;
}

// A bumpy bicubic surface over [0, 2] x [0, 1] with an interior knot in u, roughly in the
// plane z = 0 (x in [0, 20] mm, y in [0, 10] mm).
TensorSpline bumpy_surface() {
  const KnotVector ku(4, {0, 0, 0, 0, 1, 2, 2, 2, 2}), kv = KnotVector::bezier(4);
  std::vector<double> pts;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 5; ++i) pts.insert(pts.end(), {5.0 * i, 10.0 * j / 3, 0.8 * std::sin(1.3 * i + 0.7 * j)});
  return TensorSpline({ku, kv}, 3, std::move(pts));
}

// A quarter of a cylinder surface of radius r about the z axis, height h: exact, rational
// quadratic in u (angle), linear in v (height).
TensorSpline quarter_cylinder_surface(double r, double h) {
  const double c = std::numbers::sqrt2 / 2;
  std::vector<double> pts, w;
  for (int j = 0; j < 2; ++j) {
    const double xy[3][2] = {{r, 0}, {r, r}, {0, r}};
    for (int i = 0; i < 3; ++i) {
      pts.insert(pts.end(), {xy[i][0], xy[i][1], h * j});
      w.push_back(i == 1 ? c : 1.0);
    }
  }
  return TensorSpline({KnotVector::bezier(3), KnotVector::bezier(2)}, 3, std::move(pts), std::move(w));
}

double axis_distance(Vec3 p, Vec3 o, Vec3 a) {
  const Vec3 d = p - o;
  return norm(d - dot(d, a) * a);
}

TEST(Construct, ExtrusionIsTheSurfaceTranslated) {
  std::mt19937 rng(1);
  const TensorSpline s = quarter_cylinder_surface(10, 3);
  const Vec3 d{1, 2, 10};
  const Constructed c = extrude(s, {d});
  EXPECT_TRUE(c.report.exact);
  for (int i = 0; i < 200; ++i) {
    const auto t = random_params(c.volume.spline(), rng);
    const Vec3 expect = eval3(s, {t[0], t[1], 0}) + t[2] * d;
    EXPECT_LE(norm(c.volume.evaluate({t[0], t[1], t[2]}) - expect), 1e-12 * 20);
  }
  EXPECT_NE(c.report.jacobian.classification, JacobianClass::kFolded);
  EXPECT_THROW(extrude(s, {Vec3{0, 0, 0}}), ModelError);
  EXPECT_THROW(extrude(test::circle_curve({0, 0, 0}, 1), {d}), ModelError);  // not a surface
}

TEST(Construct, RuledVolumeBlendsTwoIncompatibleSurfacesLinearly) {
  std::mt19937 rng(2);
  const TensorSpline a = bumpy_surface();  // bicubic, domain [0, 2] x [0, 1], interior knot
  // A biquadratic plate with its own interior knot in v, above a.
  const KnotVector kv(3, {0, 0, 0, 0.4, 1, 1, 1});
  std::vector<double> pts;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 3; ++i) pts.insert(pts.end(), {10.0 * i, 10.0 * j / 3 + 0.3 * i, 6 + 0.5 * j * j});
  const TensorSpline b({KnotVector::bezier(3), kv}, 3, std::move(pts));
  const Constructed c = ruled(a, b);
  for (int d = 0; d < 2; ++d) {
    EXPECT_DOUBLE_EQ(c.volume.domain().lo[d], 0.0);
    EXPECT_DOUBLE_EQ(c.volume.domain().hi[d], 1.0);
  }
  for (int i = 0; i < 300; ++i) {
    const auto t = random_params(c.volume.spline(), rng);
    const Vec3 pa = eval3(a, {2 * t[0], t[1], 0}), pb = eval3(b, {t[0], t[1], 0});
    const Vec3 expect = (1 - t[2]) * pa + t[2] * pb;
    EXPECT_LE(norm(c.volume.evaluate({t[0], t[1], t[2]}) - expect), 1e-12 * 30) << t[0] << " " << t[1] << " " << t[2];
  }
}

TEST(Construct, RevolutionGivesExactCylinders) {
  std::mt19937 rng(3);
  // A rectangle r in [10, 20], z in [0, 5] in the xz plane, about the z axis; then the same
  // turned and moved onto a tilted axis.
  const TensorSpline profile = test::bilinear_plate([](double a, double b) { return Vec3{10 + 10 * a, 0, 5 * b}; });
  for (double angle : {360.0, 200.0, 45.0}) {
    const Constructed c = revolve(profile, {{0, 0, 0}, {0, 0, 1}, angle});
    EXPECT_TRUE(c.report.jacobian.classification == JacobianClass::kRightHanded ||
                c.report.jacobian.classification == JacobianClass::kLeftHanded)
        << c.report.describe();
    for (int i = 0; i < 400; ++i) {
      const auto t = random_params(c.volume.spline(), rng);
      const Vec3 p = c.volume.evaluate({t[0], t[1], t[2]});
      const double r = 10 + 10 * t[0];
      EXPECT_LE(std::abs(std::hypot(p.x, p.y) - r), 1e-12 * r);
      EXPECT_LE(std::abs(p.z - 5 * t[1]), 1e-12 * 20);
    }
    // The end of the sweep is the profile turned by the angle.
    const double rad = angle * std::numbers::pi / 180;
    for (double u : {0.0, 0.3, 1.0}) {
      const Vec3 p = c.volume.evaluate({u, 0.5, 1.0});
      const double r = 10 + 10 * u;
      EXPECT_LE(norm(p - Vec3{r * std::cos(rad), r * std::sin(rad), 2.5}), 1e-12 * 20);
    }
  }
  // Any axis: the distance to the axis and the position along it stay those of the profile.
  const Vec3 o{1, 2, 3}, a = (1.0 / std::sqrt(3.0)) * Vec3{1, 1, 1};
  const TensorSpline tilted = test::bilinear_plate([](double s, double t) {
    return Vec3{12 + 8 * s, 1 + 3 * t * s, 5 * t - 2};
  });
  RevolveParams params{o, Vec3{2, 2, 2}, 300.0};
  params.angle_direction = 0;
  const Constructed c = revolve(tilted, params);
  for (int i = 0; i < 400; ++i) {
    const auto t = random_params(c.volume.spline(), rng);
    const Vec3 p = c.volume.evaluate({t[0], t[1], t[2]});
    const Vec3 q = eval3(tilted, {t[1], t[2], 0});  // angle first: the profile's (u, v) are (v, w)
    const double r = axis_distance(q, o, a);
    EXPECT_LE(std::abs(axis_distance(p, o, a) - r), 1e-12 * r);
    EXPECT_LE(std::abs(dot(p - o, a) - dot(q - o, a)), 1e-12 * 30);
  }
}

TEST(Construct, RevolutionOfADiscGivesAnExactTorus) {
  std::mt19937 rng(4);
  const double R = 30, r = 7;
  const TensorSpline disc = test::rational_disc({R, 0, 0}, {1, 0, 0}, {0, 0, 1}, r);
  const Constructed c = revolve(disc, {{0, 0, 0}, {0, 0, 1}, 360.0});
  const auto tube_distance = [R](Vec3 p) { return std::hypot(std::hypot(p.x, p.y) - R, p.z); };
  for (int i = 0; i < 500; ++i) {
    auto t = random_params(c.volume.spline(), rng);
    // Boundary of the disc (u or v at an end): on the torus of tube radius r.
    t[static_cast<std::size_t>(i % 2)] = (i / 2) % 2 ? 1.0 : 0.0;
    EXPECT_LE(std::abs(tube_distance(c.volume.evaluate({t[0], t[1], t[2]})) - r), 1e-12 * R);
    // Inside: the distance to the axis is the profile point's.
    const auto s = random_params(c.volume.spline(), rng);
    const Vec3 q = eval3(disc, {s[0], s[1], 0});
    EXPECT_LE(
        std::abs(std::hypot(c.volume.evaluate({s[0], s[1], s[2]}).x, c.volume.evaluate({s[0], s[1], s[2]}).y) - q.x),
        1e-12 * R);
  }
  // The disc's corners are singular points of its parametrization: det J vanishes there
  // (and only on the edges through them), which the report places.
  EXPECT_NE(c.report.jacobian.classification, JacobianClass::kFolded) << c.report.describe();
}

TEST(Construct, RevolutionOnTheAxisIsDegenerateAndSaysWhere) {
  const TensorSpline profile = test::bilinear_plate([](double a, double b) { return Vec3{8 * a, 0, 4 * b}; });
  const Constructed c = revolve(profile, {{0, 0, 0}, {0, 0, 1}, 90.0});
  EXPECT_EQ(c.report.jacobian.classification, JacobianClass::kDegenerate);
  ASSERT_GT(c.report.zero.samples, 0);
  EXPECT_EQ(c.report.zero.box.lo.x, 0.0);  // the face u = 0, on the axis
  EXPECT_EQ(c.report.zero.box.hi.x, 0.0);
  EXPECT_NE(c.report.describe().find("u [0, 0]"), std::string::npos) << c.report.describe();
  EXPECT_THROW(revolve(profile, {{0, 0, 0}, {0, 0, 1}, 0.0}), ModelError);
  EXPECT_THROW(revolve(profile, {{0, 0, 0}, {0, 0, 0}, 90.0}), ModelError);
}

// The six boundary faces of a volume, each parametrized as coons.h says.
std::array<TensorSpline, 6> faces_of(const TensorSpline& vol) {
  const TensorSpline v = clamped(vol);
  const auto face = [&v](int dir, bool hi) {
    const int a = dir == 0 ? 1 : 0, b = dir == 2 ? 1 : 2;
    const int na = v.num_ctrl(a), nb = v.num_ctrl(b);
    std::vector<double> pts, w;
    for (int j = 0; j < nb; ++j)
      for (int i = 0; i < na; ++i) {
        std::array<int, 3> ijk{};
        ijk[static_cast<std::size_t>(dir)] = hi ? v.num_ctrl(dir) - 1 : 0;
        ijk[static_cast<std::size_t>(a)] = i;
        ijk[static_cast<std::size_t>(b)] = j;
        const auto p = v.point(ijk[0], ijk[1], ijk[2]);
        pts.insert(pts.end(), p.begin(), p.end());
        if (v.is_rational()) w.push_back(v.weight(ijk[0], ijk[1], ijk[2]));
      }
    return TensorSpline({v.knots(a), v.knots(b)}, 3, std::move(pts), std::move(w));
  };
  return {face(0, false), face(0, true), face(1, false), face(1, true), face(2, false), face(2, true)};
}

void expect_interpolates_faces(const Volume& vol, const std::array<TensorSpline, 6>& faces, std::mt19937& rng,
                               double tol) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int f = 0; f < 6; ++f) {
    const TensorSpline& s = faces[static_cast<std::size_t>(f)];
    const int dir = f / 2;
    for (int i = 0; i < 100; ++i) {
      const double a = U(rng), b = U(rng);
      Vec3 uvw;
      uvw[dir] = f % 2;
      uvw[dir == 0 ? 1 : 0] = a;
      uvw[dir == 2 ? 1 : 2] = b;
      const Vec3 expect = eval3(s, {s.lo(0) + a * (s.hi(0) - s.lo(0)), s.lo(1) + b * (s.hi(1) - s.lo(1)), 0});
      EXPECT_LE(norm(vol.evaluate(uvw) - expect), tol) << "face " << coons_face_name(f);
    }
  }
}

TEST(Construct, CoonsVolumeInterpolatesItsSixFacesExactly) {
  std::mt19937 rng(5);
  // The faces of a curved cubic volume, then made incompatible without changing them:
  // degrees raised, knots inserted, domains moved.
  std::array<TensorSpline, 6> faces = faces_of(test::twisted_bent_box(20, 10, 15, 5, 3).spline());
  faces[kFaceU0] = reparametrized(elevate_degree(faces[kFaceU0], 1, 2), 0, 2.0, 5.0);
  faces[kFaceV1] = insert_knot(faces[kFaceV1], 0, 0.37);
  faces[kFaceW1] = reparametrized(elevate_degree(faces[kFaceW1], 0, 1), 1, -1.0, 1.0);
  const Constructed c = coons(faces);
  expect_interpolates_faces(c.volume, faces, rng, 1e-11 * 40);
  EXPECT_EQ(c.report.jacobian.classification, JacobianClass::kRightHanded) << c.report.describe();
  // Rational faces (an exact annulus sector): interpolated exactly too.
  const std::array<TensorSpline, 6> rational = faces_of(test::annulus_sector(10, 20, 5).spline());
  expect_interpolates_faces(coons(rational).volume, rational, rng, 1e-11 * 40);
}

TEST(Construct, CoonsNamesTheFacesThatDoNotShareAnEdge) {
  std::array<TensorSpline, 6> faces = faces_of(test::twisted_bent_box(20, 10, 15, 5, 3).spline());
  faces[kFaceW1] = faces[kFaceW1].transformed([](std::span<double> p) { p[2] += 0.5; });
  try {
    coons(faces);
    FAIL() << "expected a ModelError";
  } catch (const ModelError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("faces u0 and w1"), std::string::npos) << m;
    EXPECT_NE(m.find("u=0, w=1"), std::string::npos) << m;
  }
}

TEST(Construct, ShellOfACylinderIsExactAndOfABumpySurfaceClose) {
  std::mt19937 rng(6);
  const TensorSpline cyl = quarter_cylinder_surface(10, 4);
  ShellParams p;
  p.thickness_mm = 2;
  p.side = ShellSide::kCentred;
  const Constructed c = thick_shell(cyl, p);
  EXPECT_LE(c.report.approximation_error_mm, 1e-9);
  // The normal of this parametrization points towards the axis or away: the two faces are
  // at radii 9 and 11 in some order, and w runs across the wall.
  const double r0 = std::hypot(c.volume.evaluate({0.3, 0.5, 0}).x, c.volume.evaluate({0.3, 0.5, 0}).y);
  EXPECT_NEAR(std::abs(r0 - 10), 1.0, 1e-9);
  for (int i = 0; i < 300; ++i) {
    const auto t = random_params(c.volume.spline(), rng);
    const Vec3 q = c.volume.evaluate({t[0], t[1], t[2]});
    const double expect = r0 + (20 - 2 * r0) * t[2];  // linear from r0 to 20 - r0
    EXPECT_LE(std::abs(std::hypot(q.x, q.y) - expect), 1e-9);
  }
  EXPECT_NE(c.report.jacobian.classification, JacobianClass::kFolded);

  const TensorSpline bumpy = bumpy_surface();
  ShellParams coarse;
  coarse.thickness_mm = 1.5;
  coarse.knots_per_span = 0;
  ShellParams fine = coarse;
  fine.knots_per_span = 3;
  const Constructed a = thick_shell(bumpy, coarse), b = thick_shell(bumpy, fine);
  EXPECT_FALSE(a.report.exact);
  EXPECT_GT(a.report.approximation_error_mm, 0.0);
  EXPECT_LT(b.report.approximation_error_mm, a.report.approximation_error_mm);
  EXPECT_LT(b.report.approximation_error_mm, 0.05 * fine.thickness_mm);
  // The face w = 0 is the surface itself (outside: from S to S + t n).
  for (int i = 0; i < 50; ++i) {
    const auto t = random_params(b.volume.spline(), rng);
    EXPECT_LE(norm(b.volume.evaluate({t[0], t[1], 0}) - eval3(bumpy, {t[0], t[1], 0})), 1e-10);  // the domain is kept
  }
}

TEST(Construct, ShellFacesInAnyOrderAndOrientationAreArranged) {
  std::mt19937 rng(9);
  const std::array<TensorSpline, 6> faces = faces_of(test::twisted_bent_box(20, 10, 15, 5, 3).spline());
  // Shuffled, with parameters swapped and reversed.
  const std::array<int, 2> swap{1, 0};
  const std::vector<TensorSpline> shell = {faces[kFaceV1],
                                           reversed(faces[kFaceU0], 1),
                                           permuted(faces[kFaceW1], swap),
                                           faces[kFaceW0],
                                           reversed(permuted(faces[kFaceU1], swap), 0),
                                           faces[kFaceV0]};
  const std::array<TensorSpline, 6> arranged = arrange_cube_faces(shell);
  const Constructed c = coons(arranged);
  expect_interpolates_faces(c.volume, arranged, rng, 1e-11 * 40);
  EXPECT_NE(c.report.jacobian.classification, JacobianClass::kFolded);
  // Every input face is one of the volume's faces: its centre is on the boundary.
  for (const TensorSpline& f : shell) {
    const Vec3 centre = eval3(f, {0.5, 0.5, 0});
    double best = 1e300;
    for (int face = 0; face < 6; ++face) {
      Vec3 uvw{0.5, 0.5, 0.5};
      uvw[face / 2] = face % 2;
      best = std::min(best, norm(c.volume.evaluate(uvw) - centre));
    }
    EXPECT_LE(best, 1e-10);
  }
  std::vector<TensorSpline> five(shell.begin(), shell.end() - 1);
  EXPECT_THROW(arrange_cube_faces(five), ModelError);
  std::vector<TensorSpline> moved = shell;
  moved[2] = moved[2].transformed([](std::span<double> p) { p[0] += 3; });
  EXPECT_THROW(arrange_cube_faces(moved), ModelError);
}

TEST(Construct, CoonsVolumeOfTheDuckShell) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model duck = read_model(dir / "surfaces" / "duck_brep.xml");
  std::vector<TensorSpline> shell;
  for (const Patch& p : duck.patches) shell.push_back(p.spline);
  const std::array<TensorSpline, 6> faces = arrange_cube_faces(shell);
  const Constructed c = coons(faces);
  std::mt19937 rng(10);
  expect_interpolates_faces(c.volume, faces, rng, 1e-12);
  // The duck is far from convex: its Coons volume folds (det J takes both signs), and the
  // report places the minority sign.
  const JacobianReport& j = c.report.jacobian;
  EXPECT_EQ(c.report.minority_sign.samples, std::min(j.positive, j.negative));
}

// A square section 2 x 2 mm around the local origin.
TensorSpline square_section() {
  return test::bilinear_plate([](double a, double b) { return Vec3{2 * a - 1, 2 * b - 1, 0}; });
}

TEST(Construct, SweepAlongALineWithTwistTurnsTheSection) {
  const TensorSpline line({KnotVector::bezier(2)}, 3, {0, 0, 0, 0, 0, 30});
  SweepParams p;
  p.twist_deg = 90;
  p.stations = 9;
  p.initial_x = Vec3{1, 0, 0};
  const Constructed c = sweep(square_section(), line, p);
  // Local x -> +x at the start; the frame's binormal is tangent x normal = z x x = y.
  for (double a : {0.0, 0.5, 1.0})
    for (double b : {0.0, 1.0}) {
      EXPECT_LE(norm(c.volume.evaluate({a, b, 0}) - Vec3{2 * a - 1, 2 * b - 1, 0}), 1e-12);
      // After 90 degrees: local x -> +y, local y -> -x.
      EXPECT_LE(norm(c.volume.evaluate({a, b, 1}) - Vec3{-(2 * b - 1), 2 * a - 1, 30}), 1e-12);
    }
  EXPECT_FALSE(c.report.exact);
  EXPECT_EQ(c.report.jacobian.classification, JacobianClass::kRightHanded) << c.report.describe();
  EXPECT_THROW(sweep(square_section().transformed([](std::span<double> q) { q[2] += 1; }), line, p), ModelError);
  EXPECT_THROW(sweep(square_section(), line, SweepParams{0, 3, {}, {}}), ModelError);
}

TEST(Construct, SweepOfADiscAroundACircleApproximatesATorus) {
  std::mt19937 rng(8);
  const double R = 20, r = 3;
  const TensorSpline disc = test::rational_disc({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, r);
  SweepParams p;
  p.stations = 41;
  const Constructed c = sweep(disc, test::circle_curve({0, 0, 5}, R), p);
  const double err = c.report.approximation_error_mm;
  EXPECT_LT(err, 0.01);
  const auto tube_distance = [R](Vec3 q) { return std::hypot(std::hypot(q.x, q.y) - R, q.z - 5); };
  for (int i = 0; i < 300; ++i) {
    auto t = random_params(c.volume.spline(), rng);
    t[static_cast<std::size_t>(i % 2)] = (i / 2) % 2 ? 1.0 : 0.0;  // the disc's rim
    EXPECT_NEAR(tube_distance(c.volume.evaluate({t[0], t[1], t[2]})), r, 2 * err + 1e-9);
  }
  // Closed path: the end section is the start section.
  for (double a : {0.0, 0.25, 1.0})
    for (double b : {0.0, 0.6}) EXPECT_LE(norm(c.volume.evaluate({a, b, 0}) - c.volume.evaluate({a, b, 1})), 1e-9);
}

TEST(Construct, FoldedResultsAreReportedWithTheirRegion) {
  // The top face is the bottom mirrored in u: the rulings cross at mid-height.
  const TensorSpline bottom = test::bilinear_plate([](double a, double b) { return Vec3{10 * a, 10 * b, 0}; });
  const TensorSpline top = test::bilinear_plate([](double a, double b) { return Vec3{10 - 10 * a, 10 * b, 4}; });
  const Constructed c = ruled(bottom, top);
  EXPECT_TRUE(c.report.folds());
  ASSERT_GT(c.report.minority_sign.samples, 0);
  // det J changes sign at w = 1/2: the minority samples lie on one side of it.
  const ParamBox& box = c.report.minority_sign.box;
  EXPECT_TRUE(box.lo.z > 0.5 || box.hi.z < 0.5) << c.report.describe();
  EXPECT_EQ(box.lo.x, 0.0);
  EXPECT_EQ(box.hi.x, 1.0);
  EXPECT_NE(c.report.describe().find("folded: det J"), std::string::npos) << c.report.describe();
}

}  // namespace
}  // namespace trivox
