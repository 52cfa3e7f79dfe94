// The G+Smo XML writer and the multi-patch topology: a model of every kind (curve, surface,
// rational trivariate, periodic direction) reads back with the same values; the interfaces
// found between two blocks glued in every relative orientation carry the direction map and
// orientations that G+Smo's definition gives, checked here by evaluating both patches.
#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/topology.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

std::vector<double> eval(const TensorSpline& s, std::vector<double> t) {
  std::vector<double> out(static_cast<std::size_t>(s.point_dim()));
  s.evaluate(t, out);
  return out;
}

TEST(GismoWriter, EveryKindOfPatchReadsBackWithItsValues) {
  std::mt19937 rng(5);
  const TensorSpline periodic = test::random_rational_spline(rng);  // unclamped u, periodic v
  const TensorSpline curve({KnotVector(3, {0, 0, 0, 0.4, 1, 1, 1})}, 2, {0, 0, 1, 2, 3, 1, 4, 0});
  const TensorSpline surface({KnotVector::bezier(2), KnotVector::bezier(3)}, 3,
                             {0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1, 0, 2, 0, 1, 2, 0}, {1, 1, 0.5, 2, 1, 1});
  const Model m{"mixed", {Patch{"C", 0, 0, curve}, Patch{"S", 0, 0, surface}, Patch{"V", 0, 0, periodic}}, {}};
  std::ostringstream out;
  write_gismo_xml(out, m);
  // Patches of different kinds: no <MultiPatch>, so reading takes every <Geometry>.
  EXPECT_EQ(out.str().find("MultiPatch"), std::string::npos);
  EXPECT_NE(out.str().find("<Geometry type=\"BSpline\" id=\"0\">"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("<Geometry type=\"TensorNurbs2\" id=\"1\">"), std::string::npos);
  EXPECT_NE(out.str().find("<Geometry type=\"TensorNurbs3\" id=\"2\">"), std::string::npos);
  const Model back = read_gismo_xml(out.str(), "back.xml");
  ASSERT_EQ(back.patches.size(), 3u);
  EXPECT_EQ(back.patches[0].spline.all_knots(), curve.all_knots());
  EXPECT_TRUE(std::equal(curve.points().begin(), curve.points().end(), back.patches[0].spline.points().begin(),
                         back.patches[0].spline.points().end()));
  EXPECT_TRUE(std::equal(surface.weights().begin(), surface.weights().end(), back.patches[1].spline.weights().begin(),
                         back.patches[1].spline.weights().end()));
  const TensorSpline& v = back.patches[2].spline;
  EXPECT_FALSE(v.knots(1).is_periodic());  // written as the unclamped basis it evaluates as
  for (double a : {0.0, 1.7, 3.0})
    for (double b : {3.0, 5.5, 8.0})
      for (double c : {0.0, 0.3, 1.0}) {
        const std::vector<double> p = eval(periodic, {a, b, c}), q = eval(v, {a, b, c});
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[static_cast<std::size_t>(k)], q[static_cast<std::size_t>(k)], 1e-14);
      }
}

// A trilinear block from its eight corners, [k][j][i] = corner (u = i, v = j, w = k).
TensorSpline block(const std::array<std::array<std::array<Vec3, 2>, 2>, 2>& c) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const Vec3 p = c[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
        pts.insert(pts.end(), {p.x, p.y, p.z});
      }
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector(2, {0, 0, 2, 2})}, 3, pts);
}

// The parameters of side B's point that G+Smo's interface says is side A's point s (both
// normalised to [0, 1]).
std::array<double, 3> across(const PatchInterface& f, const std::array<double, 3>& s) {
  std::array<double, 3> t{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto j = static_cast<std::size_t>(f.dir_map[i]);
    if (static_cast<int>(i) == f.first.direction())
      t[j] = f.second.at_end() ? 1.0 : 0.0;
    else
      t[j] = f.dir_orientation[i] ? s[i] : 1.0 - s[i];
  }
  return t;
}

Vec3 at(const TensorSpline& s, const std::array<double, 3>& n) {
  const std::vector<double> p = eval(s, {s.lo(0) + n[0] * (s.hi(0) - s.lo(0)), s.lo(1) + n[1] * (s.hi(1) - s.lo(1)),
                                         s.lo(2) + n[2] * (s.hi(2) - s.lo(2))});
  return {p[0], p[1], p[2]};
}

TEST(Topology, InterfacesCarryGismoDirectionMapsInEveryOrientation) {
  // Block A is the unit cube; block B the cube beside it (x in [1, 2]), parametrized by each
  // of the 48 orientation-preserving and -reversing maps of the cube onto itself.
  std::array<std::array<std::array<Vec3, 2>, 2>, 2> a{};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        a[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = {
            static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
  const TensorSpline A = block(a);
  const std::array<std::array<int, 3>, 6> perms = {{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  int checked = 0;
  for (const auto& perm : perms)
    for (int flips = 0; flips < 8; ++flips) {
      // B's parameter direction d runs along space axis perm[d], reversed where flips says.
      std::array<std::array<std::array<Vec3, 2>, 2>, 2> b{};
      for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            const int idx[3] = {i, j, k};
            Vec3 p{};
            for (int d = 0; d < 3; ++d) {
              const int bit = (flips >> d) & 1 ? 1 - idx[d] : idx[d];
              p[perm[static_cast<std::size_t>(d)]] = bit;
            }
            p.x += 1.0;
            b[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = p;
          }
      const TensorSpline B = block(b);
      const Model m{"two", {Patch{"A", 0, 0, A}, Patch{"B", 0, 0, B}}, {}};
      const PatchTopology topo = find_topology(m);
      ASSERT_EQ(topo.interfaces.size(), 1u);
      ASSERT_EQ(topo.boundary.size(), 10u);
      const PatchInterface& f = topo.interfaces[0];
      EXPECT_EQ(f.first, (PatchSide{0, 2}));  // A's u = 1 side
      EXPECT_EQ(f.second.patch, 1);
      for (double s1 : {0.0, 0.3, 1.0})
        for (double s2 : {0.0, 0.6, 1.0}) {
          const std::array<double, 3> s{1.0, s1, s2};
          const Vec3 pa = at(A, s), pb = at(B, across(f, s));
          EXPECT_NEAR(norm(pa - pb), 0.0, 1e-14) << perm[0] << perm[1] << perm[2] << " flips " << flips;
        }
      ++checked;
    }
  EXPECT_EQ(checked, 48);
}

TEST(Topology, FacesSharingOnlyTheirCornersAreNotGlued) {
  // Two blocks whose touching faces share corners and centre but bulge apart in between:
  // G+Smo's corners-and-centres rule would glue them; the 5 x 5 grid does not.
  std::vector<double> left, right;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) {
        // +0.2 at the face's edge midpoints and -0.4 at its centre: the face's corners and its
        // centre stay at x = 1, the rest bulges.
        const double bulge = (j == 1) != (k == 1) ? 0.2 : (j == 1 && k == 1 ? -0.4 : 0.0);
        left.insert(left.end(), {i == 1 ? 1.0 + bulge : 0.0, 0.5 * j, 0.5 * k});
        right.insert(right.end(), {i == 0 ? 1.0 - bulge : 2.0, 0.5 * j, 0.5 * k});
      }
  const KnotVector q = KnotVector::bezier(3);
  const Model m{"bulge",
                {Patch{"L", 0, 0, TensorSpline({KnotVector::bezier(2), q, q}, 3, left)},
                 Patch{"R", 0, 0, TensorSpline({KnotVector::bezier(2), q, q}, 3, right)}},
                {}};
  const PatchTopology topo = find_topology(m);
  EXPECT_TRUE(topo.interfaces.empty());
  EXPECT_EQ(topo.boundary.size(), 12u);
  EXPECT_THROW(find_topology(Model{"mixed",
                                   {Patch{"V", 0, 0, m.patches[0].spline},
                                    Patch{"S", 0, 0, TensorSpline({q, q}, 3, std::vector<double>(27, 0.0))}},
                                   {}}),
               ModelError);
}

}  // namespace
}  // namespace trivox
