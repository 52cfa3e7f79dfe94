// The mesh check's bounds (trivox/mesh/detail/mesh_check.h): duplicated triangles counted as
// their own defect and left out of the intersection test; a stack of coplanar faces or a
// crowded fan cut short by the budget of pairs, never passed; the stop flag read inside.
#include <gtest/gtest.h>

#include <atomic>

#include "mesh/mesh_fixtures.h"
#include "trivox/error.h"
#include "trivox/mesh/detail/mesh_check.h"
#include "trivox/mesh/sliced_mesh.h"

namespace trivox {
namespace {

SlicedMesh sliced(const test::TestMesh& m) { return SlicedMesh(m.vertices, m.triangles); }

// `copies` exports of the same box: the same vertices, each triangle repeated.
test::TestMesh box_exported(int copies) {
  test::TestMesh m = test::box_mesh({0, 0, 0}, {1, 2, 3});
  const auto once = m.triangles;
  for (int c = 1; c < copies; ++c) m.triangles.insert(m.triangles.end(), once.begin(), once.end());
  return m;
}

TEST(MeshCheckBounds, DuplicatedTrianglesAreCountedWithTheTriangleTheyRepeat) {
  const MeshCheck c = check_mesh(sliced(box_exported(3)), {1e-3, true});
  EXPECT_FALSE(c.passed());
  EXPECT_EQ(c.duplicate_triangles.count, 24u);  // 12 triangles, twice more
  EXPECT_EQ(c.duplicate_triangles.triangle, 12);
  EXPECT_EQ(c.duplicate_triangles.other, 0);
  // The copies are no intersections of their own: only the first of each is tested.
  EXPECT_EQ(c.self_intersections.count, 0u);
  EXPECT_FALSE(c.intersections_cut_short);
}

TEST(MeshCheckBounds, AReversedRepeatIsADuplicateToo) {
  test::TestMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  m.triangles.push_back({m.triangles[5][0], m.triangles[5][2], m.triangles[5][1]});
  const MeshCheck c = check_mesh(sliced(m), {1e-3, true});
  EXPECT_EQ(c.duplicate_triangles.count, 1u);
  EXPECT_EQ(c.duplicate_triangles.triangle, 12);
  EXPECT_EQ(c.duplicate_triangles.other, 5);
}

// Many coplanar triangles over one another, each with corners of its own (no weld joins them):
// every pair overlaps, so the pairs are quadratic in the triangles; the budget cuts the search
// short and the count found so far is reported as a lower bound.
TEST(MeshCheckBounds, AStackOfCoplanarFacesIsCutShortWithTheIntersectionsFound) {
  test::TestMesh m;
  const int layers = 400;
  for (int i = 0; i < layers; ++i) {
    const double s = 1e-4 * i;  // slightly shifted, so that no vertex is shared
    const int base = static_cast<int>(m.vertices.size());
    m.vertices.push_back({0 + s, 0, 0});
    m.vertices.push_back({10 + s, 0, 0});
    m.vertices.push_back({0 + s, 10, 0});
    m.triangles.push_back({base, base + 1, base + 2});
  }
  MeshCheckParams p{0.01, true};
  p.max_pair_tests = 5000;
  const MeshCheck c = check_mesh(sliced(m), p);
  EXPECT_TRUE(c.intersections_cut_short);
  EXPECT_GT(c.self_intersections.count, 0u);
  EXPECT_LE(c.self_intersections.count, 5000u);
  EXPECT_FALSE(c.passed());
  // Without a budget that small, all the pairs are found.
  const MeshCheck all = check_mesh(sliced(m), {0.01, true});
  EXPECT_FALSE(all.intersections_cut_short);
  EXPECT_EQ(all.self_intersections.count, static_cast<std::size_t>(layers * (layers - 1) / 2));
}

// A fan of slivers around one point crowds one cell: when the budget runs out before every pair
// is looked at, the mesh does not pass, though no intersection was found.
TEST(MeshCheckBounds, AMeshTooCrowdedToCheckDoesNotPass) {
  const test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 6, 400);
  MeshCheckParams p{1e-3, true};
  p.max_pair_tests = 1000;
  const MeshCheck c = check_mesh(sliced(m), p);
  EXPECT_TRUE(c.intersections_cut_short);
  EXPECT_EQ(c.self_intersections.count, 0u);
  EXPECT_FALSE(c.passed());
  EXPECT_TRUE(check_mesh(sliced(m), {1e-3, true}).passed());
}

TEST(MeshCheckBounds, TheStopFlagStopsTheIntersectionTest) {
  const test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 40, 80);
  std::atomic<bool> stop{true};
  MeshCheckParams p{1e-3, true};
  p.stop = &stop;
  EXPECT_THROW(check_mesh(sliced(m), p), CancelledError);
  stop = false;
  EXPECT_TRUE(check_mesh(sliced(m), p).passed());
}

}  // namespace
}  // namespace trivox
