// Evaluate-then-invert round trips on volumes whose Jacobian vanishes on a face: the exact
// rational cylinder sector (its u = 0 face collapses onto the axis) and a wedge built from
// a box whose two corners of one face coincide (that face collapses onto an edge).
#include <cmath>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/io/model.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {
namespace {

// Every preimage the solver reports lies in the domain, within the tolerance (as reported
// and as evaluated again here), and maps back to x.
void expect_preimages_map_back(const Volume& v, const GlobalResult& r, Vec3 x, double tol) {
  for (const Preimage& p : r.preimages) {
    EXPECT_TRUE(v.domain().contains(p.uvw));
    EXPECT_LE(p.residual, tol);
    // The reported residual comes from the evaluation with Jacobian; allow for its rounding
    // against the value-only kernel.
    EXPECT_LE(norm(v.evaluate(p.uvw) - x), tol + 1e-13 * v.bounds().diagonal());
  }
}

// The cylinder sector of radius R and height H: V(u, v, w) = (R u cos(theta(v)), R u
// sin(theta(v)), H w), where theta runs over a quarter turn with theta' >= sqrt(2) (the
// rational quadratic arc). From |V(p) - x| <= tol: |du| <= tol / R (the radii differ by at
// most the distance), |dw| <= tol / H, and off the axis, at radius rho = R u, |d theta| is
// about tol / rho, so |dv| <= 2 tol / rho bounds it with room to spare.
//
// How the solver reports x depends on rho against the tolerance. Newton stops once the
// residual is within the tolerance, so the roots found from different boxes spread over
// up to about 1.4 tol / rho in v (every angle in that range maps within the tolerance).
// Once rho >= 2 tol / same_root_relative that spread is below the distance at which roots
// are merged: one regular preimage. Within the tolerance of the axis every angle maps to x:
// the collapsed face, degenerate. In between, the roots in that range of angles are joined
// by a segment that maps within the tolerance of x, and the solver reports them as one
// collapsed set (degenerate) or, when they merge, one preimage (unique); never a fold.
TEST(InverseCollapsed, CylinderSectorRoundTrips) {
  const double R = 5.0, H = 3.0;
  const Volume v = test::cylinder_sector(R, H);
  ASSERT_EQ(check_jacobian(v).classification, JacobianClass::kDegenerate);
  const GlobalSolver solver(v);
  const GlobalSolveParams params;
  const double tol = params.newton.residual_tolerance_model;
  const double merged = 2 * tol / params.same_root_relative;  // 2e-2 at the defaults
  std::mt19937 rng(46);
  std::uniform_real_distribution<double> U(0.0, 1.0), Exponent(1.0, 13.0);
  int on_axis = 0, unique = 0, degenerate = 0, between = 0;
  for (int s = 0; s < 12000; ++s) {
    Vec3 t{U(rng), U(rng), U(rng)};
    // One sample in four at a radius from 0.1 R down to 1e-13 R, one in fifty exactly on the
    // axis; the rest uniform.
    if (s % 50 == 0) {
      t.x = 0.0;
      ++on_axis;
    } else if (s % 4 == 1) {
      t.x = std::pow(10.0, -Exponent(rng));
    }
    const Vec3 x = v.evaluate(t);
    const GlobalResult r = solver.solve(x, params);
    SCOPED_TRACE(::testing::Message() << "t = " << t.x << " " << t.y << " " << t.z);
    ASSERT_FALSE(r.preimages.empty()) << to_string(r.status);
    expect_preimages_map_back(v, r, x, tol);
    for (const Preimage& p : r.preimages) {  // (and the rounding of x itself)
      EXPECT_LE(std::abs(p.uvw.x - t.x), tol / R + 1e-15);
      EXPECT_LE(std::abs(p.uvw.z - t.z), tol / H + 1e-15);
    }
    const double rho = R * t.x;
    // A collapsed set is reported once, by one of its preimages.
    if (r.status == GlobalStatus::kDegenerate) {
      EXPECT_EQ(r.preimages.size(), 1u);
    }
    if (rho <= tol) {
      ASSERT_EQ(r.status, GlobalStatus::kDegenerate);
      ++degenerate;
    } else if (rho >= merged) {
      ASSERT_EQ(r.status, GlobalStatus::kUnique);
      ASSERT_EQ(r.preimages.size(), 1u);
      EXPECT_LE(std::abs(r.preimages[0].uvw.y - t.y), 2 * tol / rho);
      ++unique;
    } else {
      ASSERT_TRUE(r.status == GlobalStatus::kUnique || r.status == GlobalStatus::kDegenerate) << to_string(r.status);
      if (r.status == GlobalStatus::kUnique) {
        EXPECT_EQ(r.preimages.size(), 1u);
      }
      for (const Preimage& p : r.preimages) EXPECT_LE(std::abs(p.uvw.y - t.y), 2 * tol / rho);
      ++between;
    }
  }
  EXPECT_GE(unique, 8500);  // nearly all of the uniform samples
  EXPECT_GE(degenerate, on_axis + 500);
  EXPECT_GE(between, 1000);
}

// A box whose face u = 1 has its two corners (v = 0 and v = 1) at the same point in each
// layer: that face collapses onto the segment from C0 to C1, the volume is a wedge with a
// triangular section, and det J vanishes there (and only there).
Volume wedge() {
  const Vec3 A0{0, 0, 0}, B0{0, 10, 0}, C0{8, 5, 0};
  const Vec3 A1{1, -1, 6}, B1{0.5, 11, 6.5}, C1{11, 7, 6};
  const Vec3 corners[2][2][2] = {{{A0, C0}, {B0, C0}}, {{A1, C1}, {B1, C1}}};  // [k][j][i]
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const Vec3 p = corners[k][j][i];
        pts.insert(pts.end(), {p.x, p.y, p.z});
      }
  return Volume(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts));
}

TEST(InverseCollapsed, WedgeWithDuplicatedCornersFindsTheCollapsedEdge) {
  const Volume v = wedge();
  ASSERT_EQ(check_jacobian(v).classification, JacobianClass::kDegenerate);
  const GlobalSolver solver(v);
  const GlobalSolveParams params;
  const double tol = params.newton.residual_tolerance_model;
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int s = 0; s < 2000; ++s) {
    const double vv = U(rng), w = U(rng);
    SCOPED_TRACE(::testing::Message() << "v = " << vv << ", w = " << w);
    // On the collapsed edge: every v is a preimage; the solver reports the edge, at the
    // right height, as degenerate.
    const Vec3 on_edge = v.evaluate({1.0, vv, w});
    const GlobalResult edge = solver.solve(on_edge, params);
    ASSERT_EQ(edge.status, GlobalStatus::kDegenerate);
    ASSERT_FALSE(edge.preimages.empty());
    expect_preimages_map_back(v, edge, on_edge, tol);
    for (const Preimage& p : edge.preimages) {
      EXPECT_NEAR(p.uvw.x, 1.0, 1e-6);
      EXPECT_NEAR(p.uvw.z, w, 1e-6);
    }
    // Near the edge, at u = 1 - gap, where dV/dv = gap (B - A) is at least 10 gap long: the
    // parameters are recovered (v to about tol / (10 gap)). As on the cylinder's axis, one
    // regular preimage once 10 gap >= 2 tol / same_root_relative, closer in one preimage or
    // the range of v that maps within the tolerance, reported as collapsed.
    for (double gap : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6}) {
      const Vec3 t{1.0 - gap, vv, w};
      const Vec3 x = v.evaluate(t);
      const GlobalResult r = solver.solve(x, params);
      if (10 * gap >= 2 * tol / params.same_root_relative) {
        ASSERT_EQ(r.status, GlobalStatus::kUnique) << "gap " << gap;
        ASSERT_EQ(r.preimages.size(), 1u);
        EXPECT_GT(r.preimages[0].det, 0.0);
      } else {
        ASSERT_TRUE(r.status == GlobalStatus::kUnique || r.status == GlobalStatus::kDegenerate)
            << "gap " << gap << ": " << to_string(r.status);
        ASSERT_FALSE(r.preimages.empty());
      }
      expect_preimages_map_back(v, r, x, tol);
      for (const Preimage& p : r.preimages) {
        EXPECT_NEAR(p.uvw.x, t.x, 1e-8);
        EXPECT_NEAR(p.uvw.y, t.y, 1e-8 / gap);
        EXPECT_NEAR(p.uvw.z, t.z, 1e-8);
      }
    }
    // Just beyond the edge, away from the wedge: no preimage.
    const Vec3 a = v.evaluate({0.0, 0.5, w});
    const Vec3 beyond = on_edge + (1e-3 / norm(on_edge - a)) * (on_edge - a);
    EXPECT_EQ(solver.solve(beyond, params).status, GlobalStatus::kNone);
  }
}

// Real files with collapsed edges: camembert.xml's axis (the face where the radius is 0
// collapses onto it: a segment of preimages) and muscleBeam.xml's corner lines (its section is
// a disc made of one biquadratic patch, whose corners are singular: V is flat to second order
// there, so a whole neighbourhood of parameters maps within the tolerance). Each point answers
// degenerate with one preimage, within the box budget: without the search skipping the boxes
// joined to a root already found, the first took thousands of near-duplicate roots and the
// second ran out of boxes (incomplete).
TEST(InverseCollapsed, SharedFilesAnswerDegenerateWithOnePreimage) {
  const std::filesystem::path data = test::shared_data_dir();
  if (data.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  struct Case {
    const char* file;
    Vec3 x;
  };
  for (const Case& c :
       {Case{"volumes/gismo/camembert.xml", {0, 0, 0.5}}, Case{"volumes/gismo/camembert.xml", {0, 0, 0.3}},
        Case{"volumes/gismo/camembert.xml", {1e-9, 0, 0.5}}, Case{"volumes/gismo/muscleBeam.xml", {0.5, 0, 0.05}},
        Case{"volumes/gismo/muscleBeam.xml", {0.25, 0.05, 0}}}) {
    SCOPED_TRACE(::testing::Message() << c.file << " at " << c.x.x << " " << c.x.y << " " << c.x.z);
    const Model m = read_model(data / c.file);
    const Volume v(m.patches[0].spline);
    const GlobalSolver solver(v);
    const GlobalSolveParams params;
    const GlobalResult r = solver.solve(c.x, params);
    EXPECT_EQ(r.status, GlobalStatus::kDegenerate) << to_string(r.status);
    ASSERT_EQ(r.preimages.size(), 1u);
    EXPECT_LT(r.boxes_visited, params.max_boxes);
    expect_preimages_map_back(v, r, c.x, params.newton.residual_tolerance_model);
  }
}

}  // namespace
}  // namespace trivox
