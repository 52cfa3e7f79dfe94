// The checks of a triangle mesh (trivox/mesh/detail/mesh_check.h): each defect made on purpose,
// counted, with its example triangle; the intersection test on its own, at the boundary of
// its tolerance; the orientation repair; the signed cut (SlicedMesh::cut with directions).
#include <gtest/gtest.h>

#include <random>

#include "mesh/mesh_fixtures.h"
#include "trivox/mesh/detail/mesh_check.h"
#include "trivox/mesh/sliced_mesh.h"

namespace trivox {
namespace {

SlicedMesh sliced(const test::TestMesh& m) { return SlicedMesh(m.vertices, m.triangles); }

test::TestMesh joined(test::TestMesh a, const test::TestMesh& b) {
  const int base = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

TEST(MeshCheck, AClosedOrientedMeshPasses) {
  for (const test::TestMesh& m : {test::box_mesh({0, 0, 0}, {1, 2, 3}), test::sphere_mesh({1, 2, 3}, 2, 12, 20)}) {
    const MeshCheck c = check_mesh(sliced(m), {1e-3, true});
    EXPECT_TRUE(c.passed());
    EXPECT_EQ(c.open_edges.triangle, -1);
  }
}

// A fine sphere in float coordinates, at tolerances up to a coarse pixel: the fans around
// its poles are nearly flat, and their triangles, which share only the pole, must not read as
// crossing (their corners lie within a thousandth of the tolerance of each other's planes
// only in part).
TEST(MeshCheck, AFineSphereInFloatsPassesAtEveryTolerance) {
  test::TestMesh m = test::sphere_mesh({3.1, 2.3, 4.2}, 4, 40, 64);
  for (Vec3& p : m.vertices) p = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
  for (const double tolerance : {0.0, 1e-3, 0.01, 0.125, 0.5}) {
    const MeshCheck c = check_mesh(sliced(m), {tolerance, true});
    EXPECT_EQ(c.self_intersections.count, 0u)
        << tolerance << ": e.g. " << c.self_intersections.triangle << " and " << c.self_intersections.other;
  }
}

TEST(MeshCheck, AMissingTriangleLeavesThreeOpenEdges) {
  test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 8, 12);
  m.triangles.erase(m.triangles.begin() + 40);
  const MeshCheck c = check_mesh(sliced(m), {});
  EXPECT_FALSE(c.closed());
  EXPECT_EQ(c.open_edges.count, 3u);
  // The lowest-numbered triangle beside the hole.
  int lowest = 1 << 30;
  const test::TestMesh whole = test::sphere_mesh({0, 0, 0}, 1, 8, 12);
  const auto hole = whole.triangles[40];
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    int shared = 0;
    for (int u : m.triangles[t])
      for (int v : hole) shared += u == v;
    if (shared >= 2) lowest = std::min(lowest, static_cast<int>(t));
  }
  EXPECT_EQ(c.open_edges.triangle, lowest);
  EXPECT_EQ(c.misoriented_edges.count, 0u);
}

TEST(MeshCheck, AFlippedTriangleIsMisorientedAndRepaired) {
  test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 8, 12);
  std::swap(m.triangles[17][0], m.triangles[17][1]);
  const MeshCheck c = check_mesh(sliced(m), {});
  EXPECT_TRUE(c.closed());
  EXPECT_EQ(c.misoriented_edges.count, 3u);
  // Its three neighbours and itself have misoriented edges; the lowest of them is named.
  EXPECT_LE(c.misoriented_edges.triangle, 17);
  std::vector<SlicedMesh::Triangle> tris = m.triangles;
  EXPECT_EQ(orient_consistently(m.vertices, tris), 1u);
  // The triangle runs its original cycle again (from another corner: the repair swaps two).
  const auto want = test::sphere_mesh({0, 0, 0}, 1, 8, 12).triangles;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    auto a = tris[t];
    while (a[0] != want[t][0]) std::rotate(a.begin(), a.begin() + 1, a.end());
    EXPECT_EQ(a, want[t]) << t;
  }
}

TEST(MeshCheck, OrientationRepairKeepsTheMajorityOfEachComponent) {
  // An outer sphere, outward, and a cavity sphere inside it, inward (a hollow ball): each has
  // some triangles flipped; the repair turns those back and leaves the cavity inward.
  test::TestMesh outer = test::sphere_mesh({0, 0, 0}, 2, 10, 16);
  test::TestMesh inner = test::sphere_mesh({0, 0, 0}, 1, 10, 16);
  for (auto& t : inner.triangles) std::swap(t[1], t[2]);
  const test::TestMesh want = joined(outer, inner);
  test::TestMesh m = want;
  std::mt19937 rng(7);
  std::size_t flipped = 0;
  for (auto& t : m.triangles)
    if (rng() % 10 == 0) {
      std::swap(t[0], t[1]);
      ++flipped;
    }
  ASSERT_GT(flipped, 5u);
  std::vector<SlicedMesh::Triangle> tris = m.triangles;
  EXPECT_EQ(orient_consistently(m.vertices, tris), flipped);
  // The same orientation as intended (each triangle its original cycle).
  for (std::size_t t = 0; t < tris.size(); ++t) {
    auto a = tris[t], b = want.triangles[t];
    while (a[0] != b[0]) std::rotate(a.begin(), a.begin() + 1, a.end());
    EXPECT_EQ(a, b) << t;
  }
}

TEST(MeshCheck, ADuplicatedFaceIsNonManifold) {
  test::TestMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  m.triangles.push_back(m.triangles[4]);
  const MeshCheck c = check_mesh(sliced(m), {});
  EXPECT_EQ(c.nonmanifold_edges.count, 3u);
  // Edge (0, 1) of the copied triangle 4 is also triangle 0's: the lowest triangle is named.
  EXPECT_EQ(c.nonmanifold_edges.triangle, 0);
  EXPECT_FALSE(c.closed());
}

TEST(MeshCheck, OverlappingBoxesIntersectAndSeparateOnesDoNot) {
  const test::TestMesh a = test::box_mesh({0, 0, 0}, {2, 2, 2});
  const MeshCheck crossing = check_mesh(sliced(joined(a, test::box_mesh({1, 1, 1}, {3, 3, 3}))), {1e-3, true});
  EXPECT_TRUE(crossing.closed());
  EXPECT_GT(crossing.self_intersections.count, 0u);
  EXPECT_LT(crossing.self_intersections.triangle, 12);
  EXPECT_GE(crossing.self_intersections.other, 12);
  EXPECT_EQ(
      check_mesh(sliced(joined(a, test::box_mesh({2.5, 0, 0}, {3, 1, 1}))), {1e-3, true}).self_intersections.count, 0u);
  // A corner poking 0.004 into the box in x, y and z: its faces cross the box's along
  // segments of about 0.006, which pass a tolerance of 0.01 and not one of 0.001.
  const test::TestMesh close = joined(a, test::box_mesh({1.996, 1.996, 1.996}, {3, 3, 3}));
  EXPECT_EQ(check_mesh(sliced(close), {0.01, true}).self_intersections.count, 0u);
  EXPECT_GT(check_mesh(sliced(close), {0.001, true}).self_intersections.count, 0u);
  EXPECT_EQ(check_mesh(sliced(close), {0.001, false}).self_intersections.count, 0u);
}

TEST(MeshCheck, ManyTrianglesAgainstAllPairs) {
  // Two spheres that overlap, and a large triangle through both: the grid's pairs against
  // every pair tested.
  test::TestMesh m = joined(test::sphere_mesh({0, 0, 0}, 1, 12, 18), test::sphere_mesh({1.2, 0.3, 0.1}, 0.8, 9, 14));
  const int base = static_cast<int>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {{-3, -3, 0.05}, {4, -3, 0.07}, {0, 4, 0.06}});
  m.triangles.push_back({base, base + 1, base + 2});
  const double tol = 1e-4;
  const MeshCheck c = check_mesh(sliced(m), {tol, true});
  std::size_t pairs = 0;
  std::pair<int, int> first{-1, -1};
  for (std::size_t s = 0; s < m.triangles.size(); ++s)
    for (std::size_t t = s + 1; t < m.triangles.size(); ++t) {
      int shared = 0;
      for (int u : m.triangles[s])
        for (int v : m.triangles[t]) shared += u == v;
      if (shared >= 2) continue;
      auto corners = [&](std::size_t k) {
        return std::array<Vec3, 3>{m.vertices[static_cast<std::size_t>(m.triangles[k][0])],
                                   m.vertices[static_cast<std::size_t>(m.triangles[k][1])],
                                   m.vertices[static_cast<std::size_t>(m.triangles[k][2])]};
      };
      if (triangles_intersect(corners(s), corners(t), tol)) {
        if (pairs++ == 0) first = {static_cast<int>(s), static_cast<int>(t)};
      }
    }
  EXPECT_GT(pairs, 50u);
  EXPECT_EQ(c.self_intersections.count, pairs);
  EXPECT_EQ(c.self_intersections.triangle, first.first);
  EXPECT_EQ(c.self_intersections.other, first.second);
}

TEST(TrianglesIntersect, CrossingTouchingAndSharingCorners) {
  const std::array<Vec3, 3> flat{Vec3{0, 0, 0}, Vec3{4, 0, 0}, Vec3{0, 4, 0}};
  // Through its middle, crossing along 1 (x from 0.5 to 1.5 at y = 1).
  const std::array<Vec3, 3> through{Vec3{0.5, 1, -1}, Vec3{1.5, 1, -1}, Vec3{1, 1, 1}};
  EXPECT_TRUE(triangles_intersect(flat, through, 0));
  EXPECT_TRUE(triangles_intersect(through, flat, 0.4));
  EXPECT_FALSE(triangles_intersect(flat, through, 0.6));
  // Standing on it at one point, and above it.
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{1, 1, 0}, Vec3{2, 1, 1}, Vec3{1, 2, 1}}, 0));
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{1, 1, 0.1}, Vec3{2, 1, 1}, Vec3{1, 2, 1}}, 0));
  // Sharing a corner: a fan around it does not intersect; a triangle that dives through
  // from the shared corner does.
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{0, 0, 0}, Vec3{0, -1, 1}, Vec3{-1, 0, 1}}, 0));
  EXPECT_TRUE(triangles_intersect(flat, {Vec3{0, 0, 0}, Vec3{2, 1, -1}, Vec3{1, 2, 1}}, 0));
  // Coplanar: overlapping (width about 1), beside each other, sharing only a corner.
  EXPECT_TRUE(triangles_intersect(flat, {Vec3{1, 1, 0}, Vec3{5, 1, 0}, Vec3{1, 5, 0}}, 0.1));
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{1, 1, 0}, Vec3{5, 1, 0}, Vec3{1, 5, 0}}, 1.0));
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{5, 0, 0}, Vec3{9, 0, 0}, Vec3{5, 4, 0}}, 0));
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{0, 0, 0}, Vec3{-4, 0, 0}, Vec3{0, -4, 0}}, 0));
  // Two triangles of a flat face with float coordinates, far from the origin, that share
  // only a corner (a nut's top face): the overlap clipped down to that corner must measure as
  // a point, not as the rounding of its coordinates' products (which passed 0.01 mm); and the
  // same with one lifted by 1e-9, nearly but not exactly coplanar.
  const std::array<Vec3, 3> fan_a{Vec3{-0.13085027039051056, 2.7468852996826172, 1.7999999523162842},
                                  Vec3{-0.39136579632759094, -2.7220089435577393, 1.7999999523162842},
                                  Vec3{-0.13085027039051056, -2.7468852996826172, 1.7999999523162842}};
  std::array<Vec3, 3> fan_b{Vec3{2.7375478744506836, -0.2614041268825531, 1.7999999523162842},
                            Vec3{-0.13085027039051056, -2.7468852996826172, 1.7999999523162842},
                            Vec3{2.7003040313720703, -0.52044093608856201, 1.7999999523162842}};
  EXPECT_FALSE(triangles_intersect(fan_a, fan_b, 0.01));
  EXPECT_FALSE(triangles_intersect(fan_a, fan_b, 0));
  fan_b[0].z += 1e-9;
  EXPECT_FALSE(triangles_intersect(fan_a, fan_b, 0.01));
  // Moved onto the other one, the same triangle overlaps it.
  for (Vec3& p : fan_b) p = p + Vec3{-1.5, 0.5, 0};
  EXPECT_TRUE(triangles_intersect(fan_a, fan_b, 0.01));
  // A degenerate triangle has no plane and crosses nothing.
  EXPECT_FALSE(triangles_intersect(flat, {Vec3{1, 1, -1}, Vec3{1, 1, 0}, Vec3{1, 1, 1}}, 0));
}

// The direction of each segment of a cut: for a closed outward mesh, the crossings beyond a
// point add up to 1 inside and 0 outside, on every row.
TEST(SlicedMeshCut, DirectionsGiveTheWindingNumber) {
  const test::TestMesh m = test::sphere_mesh({0.1, -0.2, 0.05}, 1, 14, 22);
  const SlicedMesh mesh(m.vertices, m.triangles);
  std::vector<Segment2> segments, plain;
  std::vector<int> directions;
  for (double z : {-0.9, -0.3, 0.0, 0.05, 0.61}) {
    mesh.cut(z, segments, directions);
    mesh.cut(z, plain);
    ASSERT_EQ(segments.size(), plain.size());
    for (std::size_t k = 0; k < plain.size(); ++k) {
      EXPECT_EQ(std::memcmp(&segments[k], &plain[k], sizeof(Segment2)), 0);
      EXPECT_TRUE(directions[k] == 1 || directions[k] == -1);
    }
    for (double y = -1.3; y <= 1.3; y += 0.0731)
      for (double x = -1.3; x <= 1.3; x += 0.0913) {
        int w = 0, parity = 0;
        double xc;
        for (std::size_t k = 0; k < segments.size(); ++k)
          if (crosses_row(segments[k], y, xc) && xc > x) {
            w += crossing_winding(segments[k], directions[k]);
            ++parity;
          }
        EXPECT_EQ(w, parity % 2) << x << ", " << y << ", " << z;
      }
  }
  // Turned inside out, the windings are -1 inside.
  test::TestMesh inv = m;
  for (auto& t : inv.triangles) std::swap(t[1], t[2]);
  const SlicedMesh inside_out(inv.vertices, inv.triangles);
  inside_out.cut(0.05, segments, directions);
  int w = 0;
  double xc;
  for (std::size_t k = 0; k < segments.size(); ++k)
    if (crosses_row(segments[k], -0.2, xc) && xc > 0.1) w += crossing_winding(segments[k], directions[k]);
  EXPECT_EQ(w, -1);
}

}  // namespace
}  // namespace trivox
