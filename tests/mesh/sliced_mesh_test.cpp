// SlicedMesh: the cut against a brute-force cut of every triangle, closed cross-sections at
// degenerate heights, the slab, the mapped mesh and the edge count, on an axis box and on a
// perturbed sphere of many triangles.
#include "trivox/mesh/sliced_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace trivox {
namespace {

// The 12 triangles of the box [0,1] x [0,2] x [0,3], outward or not (the cut ignores it).
SlicedMesh box_mesh() {
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k) v.push_back({double(k & 1), 2.0 * ((k >> 1) & 1), 3.0 * ((k >> 2) & 1)});
  const std::vector<SlicedMesh::Triangle> t = {{0, 1, 3}, {0, 3, 2}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                               {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 3, 7}, {1, 7, 5}};
  return SlicedMesh(v, t);
}

// A UV sphere of radius 1 with every vertex moved radially by up to 10 %: a closed mesh of
// `rings` x `sectors` quads whose triangles span many height buckets.
SlicedMesh bumpy_sphere(int rings, int sectors, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> bump(0.9, 1.1);
  std::vector<Vec3> v = {{0, 0, -1}, {0, 0, 1}};
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * s / sectors, k = bump(rng);
      v.push_back({k * std::sin(th) * std::cos(ph), k * std::sin(th) * std::sin(ph), -k * std::cos(th)});
    }
  auto at = [&](int r, int s) { return 2 + (r - 1) * sectors + (s % sectors); };
  std::vector<SlicedMesh::Triangle> t;
  for (int s = 0; s < sectors; ++s) {
    t.push_back({0, at(1, s + 1), at(1, s)});
    t.push_back({1, at(rings - 1, s), at(rings - 1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      t.push_back({at(r, s), at(r, s + 1), at(r + 1, s + 1)});
      t.push_back({at(r, s), at(r + 1, s + 1), at(r + 1, s)});
    }
  }
  return SlicedMesh(v, t);
}

// The cut by testing every triangle: the reference for cut() and near().
std::vector<Segment2> brute_cut(const SlicedMesh& m, double z) {
  std::vector<Segment2> out;
  Segment2 s;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (m.cut_triangle(static_cast<int>(t), z, s)) out.push_back(s);
  return out;
}

bool same(const std::vector<Segment2>& a, const std::vector<Segment2>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].x0 != b[i].x0 || a[i].y0 != b[i].y0 || a[i].x1 != b[i].x1 || a[i].y1 != b[i].y1) return false;
  return true;
}

// Every endpoint of a closed cross-section is shared by an even number of segments, bit for
// bit (two, or more where the plane passes through a vertex).
bool closed_loops(const std::vector<Segment2>& segs) {
  std::map<std::pair<double, double>, int> ends;
  for (const Segment2& s : segs) {
    ++ends[{s.x0, s.y0}];
    ++ends[{s.x1, s.y1}];
  }
  return std::all_of(ends.begin(), ends.end(), [](const auto& e) { return e.second % 2 == 0; });
}

TEST(SlicedMesh, CutEqualsTheCutOfEveryTriangleAndIsClosed) {
  const SlicedMesh m = bumpy_sphere(60, 80, 7);
  ASSERT_EQ(m.odd_edges(), 0u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> zs(-1.2, 1.2);
  std::vector<Segment2> cut;
  int crossed = 0;
  for (int k = 0; k < 300; ++k) {
    // Random heights and the vertices' own heights (a vertex on the plane).
    const double z = k % 2 ? zs(rng) : m.vertices()[static_cast<std::size_t>(k) % m.vertex_count()].z;
    m.cut(z, cut);
    ASSERT_TRUE(same(cut, brute_cut(m, z))) << "z = " << z;
    ASSERT_TRUE(closed_loops(cut)) << "z = " << z;
    crossed += !cut.empty();
  }
  EXPECT_GT(crossed, 200);
}

TEST(SlicedMesh, AVertexOnThePlaneCountsAsAbove) {
  const SlicedMesh m = box_mesh();
  std::vector<Segment2> cut;
  m.cut(0.0, cut);  // the bottom face: every vertex at or above the plane
  EXPECT_TRUE(cut.empty());
  m.cut(3.0, cut);  // the top face: the side walls cross it at their top vertices
  EXPECT_EQ(cut.size(), 8u);
  EXPECT_TRUE(closed_loops(cut));
  m.cut(1.5, cut);
  EXPECT_EQ(cut.size(), 8u);
  EXPECT_TRUE(closed_loops(cut));
  double length = 0;
  for (const Segment2& s : cut) length += std::hypot(s.x1 - s.x0, s.y1 - s.y0);
  EXPECT_NEAR(length, 6.0, 1e-12);  // the perimeter of the 1 x 2 rectangle
}

TEST(SlicedMesh, SlabListsEveryTriangleMeetingItOnce) {
  const SlicedMesh m = bumpy_sphere(40, 50, 11);
  std::vector<std::array<Vec3, 3>> slab;
  for (const auto& [z0, z1] :
       {std::pair{-0.31, -0.29}, std::pair{0.0, 0.5}, std::pair{-2.0, 2.0}, std::pair{1.5, 2.0}}) {
    m.slab(z0, z1, slab);
    std::size_t expected = 0;
    for (const auto& t : m.triangles()) {
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (int v : t) {
        lo = std::min(lo, m.vertices()[static_cast<std::size_t>(v)].z);
        hi = std::max(hi, m.vertices()[static_cast<std::size_t>(v)].z);
      }
      expected += !(hi < z0 || lo > z1);
    }
    EXPECT_EQ(slab.size(), expected) << z0 << " " << z1;
  }
}

TEST(SlicedMesh, MappedMovesVerticesAndKeepsTriangles) {
  const SlicedMesh m = box_mesh();
  const SlicedMesh moved = m.mapped([](Vec3 p) { return Vec3{p.x + 10, p.y, p.z + 1}; });
  EXPECT_EQ(moved.triangles(), m.triangles());
  EXPECT_EQ(moved.bounds().lo.x, 10.0);
  EXPECT_EQ(moved.bounds().hi.z, 4.0);
  std::vector<Segment2> a, b;
  m.cut(1.25, a);
  moved.cut(2.25, b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].x0 + 10, b[i].x0);
}

TEST(SlicedMesh, OddEdgesCountTheBorderOfAnOpenMesh) {
  const SlicedMesh closed = box_mesh();
  EXPECT_EQ(closed.odd_edges(), 0u);
  std::vector<SlicedMesh::Triangle> t = closed.triangles();
  t.pop_back();  // one triangle of a side: its three edges now border one triangle each
  EXPECT_EQ(SlicedMesh(closed.vertices(), t).odd_edges(), 3u);
}

TEST(SlicedMesh, HeightsFarOutsideAndNotANumberFindNothing) {
  // A mesh far from the origin, and planes at the limits of a double: no bucket index
  // overflows and nothing is found.
  const SlicedMesh m = box_mesh().mapped([](Vec3 p) { return Vec3{p.x, p.y, 1e300 + p.z * 1e290}; });
  std::vector<Segment2> cut;
  for (double z : {-std::numeric_limits<double>::max(), 0.0, 1e308, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    m.cut(z, cut);
    EXPECT_TRUE(cut.empty()) << z;
    EXPECT_TRUE(m.near(z).empty()) << z;
  }
  m.cut(1e300 + 1.5e290, cut);
  EXPECT_EQ(cut.size(), 8u);
  const SlicedMesh empty;
  EXPECT_TRUE(empty.near(0.0).empty());
}

}  // namespace
}  // namespace trivox
