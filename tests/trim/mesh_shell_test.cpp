// Mesh trims as shells (trivox/trim/detail/shell_mesh.h): the even-odd rule against exact rays; the
// winding-number rule's fast path (signed crossings of the mesh closed by cones, the cones'
// share only near them) against the generalized winding number summed over every triangle,
// on meshes with holes; the orientation repair; overlapping parts and cavities.
#include <gtest/gtest.h>

#include <random>

#include "mesh/mesh_fixtures.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {
namespace {

TrimShell mesh_shell(const test::TestMesh& m, InsideRule rule) {
  TrimShell s;
  s.name = "test mesh";
  s.mesh = std::make_shared<SlicedMesh>(m.vertices, m.triangles);
  s.rule = rule;
  return s;
}

std::vector<std::array<Vec3, 3>> soup(const test::TestMesh& m) {
  std::vector<std::array<Vec3, 3>> out;
  for (const auto& t : m.triangles)
    out.push_back({m.vertices[static_cast<std::size_t>(t[0])], m.vertices[static_cast<std::size_t>(t[1])],
                   m.vertices[static_cast<std::size_t>(t[2])]});
  return out;
}

test::TestMesh joined(test::TestMesh a, const test::TestMesh& b) {
  const int base = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

std::vector<Vec3> random_points(Box3 box, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Vec3> out;
  const Vec3 grow = 0.2 * (box.hi - box.lo);
  std::uniform_real_distribution<double> ux(box.lo.x - grow.x, box.hi.x + grow.x),
      uy(box.lo.y - grow.y, box.hi.y + grow.y), uz(box.lo.z - grow.z, box.hi.z + grow.z);
  for (int i = 0; i < n; ++i) out.push_back({ux(rng), uy(rng), uz(rng)});
  return out;
}

TEST(MeshShell, EvenOddAgreesWithExactRays) {
  const test::TestMesh m = test::sphere_mesh({0.3, -0.1, 0.2}, 2, 16, 24);
  const ShellMesh shell(mesh_shell(m, InsideRule::kEvenOdd));
  EXPECT_FALSE(shell.winding());
  EXPECT_EQ(shell.open_edges(), 0u);
  EXPECT_EQ(shell.triangle_count(), m.triangles.size());
  const test::ExactRays rays(soup(m));
  int inside = 0;
  for (const Vec3& p : random_points(shell.bounds(), 4000, 1)) {
    bool degenerate;
    double nearest;
    const bool want = rays.inside(p, degenerate, nearest);
    ASSERT_FALSE(degenerate);
    if (nearest < 1e-9) continue;
    EXPECT_EQ(shell.contains(p), want) << p.x << ", " << p.y << ", " << p.z;
    inside += want;
  }
  EXPECT_GT(inside, 500);
}

TEST(MeshShell, WindingOnAClosedMeshIsTheEvenOddRule) {
  const test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 10, 14);
  const ShellMesh even_odd(mesh_shell(m, InsideRule::kEvenOdd));
  const ShellMesh winding(mesh_shell(m, InsideRule::kWindingNumber));
  EXPECT_TRUE(winding.winding());
  EXPECT_EQ(winding.cone_count(), 0u);
  EXPECT_EQ(winding.flipped_triangles(), 0u);
  for (const Vec3& p : random_points(even_odd.bounds(), 3000, 2)) EXPECT_EQ(winding.contains(p), even_odd.contains(p));
}

// Holes: a missing triangle, a missing band of four, and the whole top cap cut off (a bowl).
// The fast path against the sum over every triangle, at points where the generalized winding
// number is not within 1e-9 of 1/2.
TEST(MeshShell, WindingFastPathAgreesWithTheSumOverEveryTriangle) {
  test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 12, 16);
  const int sectors = 16;
  std::vector<std::size_t> drop = {40, 100, 101, 102, 103};
  // The cap: the last ring of triangles around the top vertex.
  for (int j = 0; j < sectors; ++j) drop.push_back(m.triangles.size() - 1 - static_cast<std::size_t>(j));
  std::sort(drop.rbegin(), drop.rend());
  for (std::size_t t : drop) m.triangles.erase(m.triangles.begin() + static_cast<std::ptrdiff_t>(t));
  const ShellMesh shell(mesh_shell(m, InsideRule::kWindingNumber));
  EXPECT_EQ(shell.cone_count(), 3u);
  EXPECT_EQ(shell.open_edges(), 0u);  // not counted: the cones close it
  std::size_t checked = 0, inside = 0, near_cones = 0;
  for (const Vec3& p : random_points(shell.bounds(), 6000, 3)) {
    const double g = shell.generalized_winding_number(p);
    if (std::abs(g - 0.5) < 1e-9) continue;
    ++checked;
    inside += g >= 0.5;
    EXPECT_EQ(shell.contains(p), g >= 0.5) << p.x << ", " << p.y << ", " << p.z << ": " << g;
    near_cones += std::abs(g - std::round(g)) > 0.01;
  }
  EXPECT_GT(checked, 5000u);
  EXPECT_GT(inside, 1000u);
  EXPECT_GT(near_cones, 200u);  // the sum mattered somewhere (inside the bowl's mouth)
}

TEST(MeshShell, FlippedTrianglesAndAnInsideOutMeshAreRepaired) {
  const test::TestMesh m = test::sphere_mesh({0, 0, 0}, 1, 10, 14);
  const ShellMesh want(mesh_shell(m, InsideRule::kEvenOdd));
  test::TestMesh flipped = m;
  for (std::size_t t = 0; t < flipped.triangles.size(); t += 9)
    std::swap(flipped.triangles[t][0], flipped.triangles[t][2]);
  test::TestMesh inside_out = m;
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  const ShellMesh a(mesh_shell(flipped, InsideRule::kWindingNumber));
  const ShellMesh b(mesh_shell(inside_out, InsideRule::kWindingNumber));
  EXPECT_EQ(a.flipped_triangles(), (m.triangles.size() + 8) / 9);
  for (const Vec3& p : random_points(want.bounds(), 3000, 4)) {
    EXPECT_EQ(a.contains(p), want.contains(p));
    EXPECT_EQ(b.contains(p), want.contains(p));
  }
}

TEST(MeshShell, OverlappingPartsAreTheirUnionAndACavityStaysEmpty) {
  const test::TestMesh s1 = test::sphere_mesh({0, 0, 0}, 1, 12, 16), s2 = test::sphere_mesh({0.8, 0.2, 0}, 1, 12, 16);
  const ShellMesh one(mesh_shell(s1, InsideRule::kEvenOdd)), two(mesh_shell(s2, InsideRule::kEvenOdd));
  const ShellMesh union_(mesh_shell(joined(s1, s2), InsideRule::kWindingNumber));
  const ShellMesh xor_(mesh_shell(joined(s1, s2), InsideRule::kEvenOdd));
  int both = 0;
  for (const Vec3& p : random_points(union_.bounds(), 4000, 5)) {
    const bool a = one.contains(p), b = two.contains(p);
    EXPECT_EQ(union_.contains(p), a || b);
    EXPECT_EQ(xor_.contains(p), a != b);
    both += a && b;
  }
  EXPECT_GT(both, 100);  // the lens where they overlap was sampled
  // A hollow ball: the cavity's sphere faces inward, and stays a cavity.
  test::TestMesh cavity = test::sphere_mesh({0, 0, 0}, 0.5, 10, 14);
  for (auto& t : cavity.triangles) std::swap(t[1], t[2]);
  const ShellMesh hollow(mesh_shell(joined(s1, cavity), InsideRule::kWindingNumber));
  EXPECT_FALSE(hollow.contains({0.01, 0.02, 0.03}));
  EXPECT_TRUE(hollow.contains({0.75, 0.02, 0.03}));
  EXPECT_FALSE(hollow.contains({1.5, 0.02, 0.03}));
}

}  // namespace
}  // namespace trivox
