#include "trivox/mesh/detail/mesh_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "trivox/cancel.h"
#include "trivox/error.h"

namespace trivox {

namespace {

constexpr const char* kChecking = "checking a mesh for self-intersections";

// One use of an edge by a triangle: the edge's vertices (lower first), the triangle, and
// whether the triangle runs along it from the lower vertex to the higher.
struct EdgeUse {
  std::uint64_t key;
  int triangle;
  bool forward;
};

std::vector<EdgeUse> edge_uses(const std::vector<SlicedMesh::Triangle>& triangles, StopPoll& stop) {
  std::vector<EdgeUse> uses;
  uses.reserve(triangles.size() * 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::size_t e = 0; e < 3; ++e) {
      stop.step();
      const auto a = static_cast<std::uint32_t>(triangles[t][e]),
                 b = static_cast<std::uint32_t>(triangles[t][(e + 1) % 3]);
      const std::uint64_t lo = std::min(a, b), hi = std::max(a, b);
      uses.push_back({(lo << 32) | hi, static_cast<int>(t), a < b});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });
  return uses;
}

void note(MeshDefect& d, int triangle, int other = -1) {
  ++d.count;
  if (d.triangle < 0 || triangle < d.triangle || (triangle == d.triangle && other < d.other)) {
    d.triangle = triangle;
    d.other = other;
  }
}

double area2(const std::vector<Vec3>& v, const SlicedMesh::Triangle& t) {
  const Vec3 a = v[static_cast<std::size_t>(t[0])], b = v[static_cast<std::size_t>(t[1])],
             c = v[static_cast<std::size_t>(t[2])];
  return norm(cross(b - a, c - a));
}

// The points where triangle `p` meets the plane its signed distances `d` refer to: its
// vertices on the plane and the crossings of its edges.
int plane_points(const std::array<Vec3, 3>& p, const double d[3], Vec3 out[4]) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (d[i] == 0) out[n++] = p[static_cast<std::size_t>(i)];
    if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
      const double u = d[i] / (d[i] - d[j]);
      out[n++] = p[static_cast<std::size_t>(i)] + u * (p[static_cast<std::size_t>(j)] - p[static_cast<std::size_t>(i)]);
    }
  }
  return n;
}

// The part of convex polygon `poly` (2D) on the left of the directed line a -> b.
std::vector<std::array<double, 2>> clip(const std::vector<std::array<double, 2>>& poly, std::array<double, 2> a,
                                        std::array<double, 2> b) {
  std::vector<std::array<double, 2>> out;
  auto side = [&](const std::array<double, 2>& p) {
    return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
  };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const auto& p = poly[i];
    const auto& q = poly[(i + 1) % poly.size()];
    const double sp = side(p), sq = side(q);
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) {
      const double u = sp / (sp - sq);
      out.push_back({p[0] + u * (q[0] - p[0]), p[1] + u * (q[1] - p[1])});
    }
  }
  return out;
}

// Coplanar triangles: the width of their overlap (twice its area over its perimeter).
double coplanar_overlap_width(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b, Vec3 normal) {
  // Drop the coordinate the plane is steepest along.
  const double ax = std::abs(normal.x), ay = std::abs(normal.y), az = std::abs(normal.z);
  const int drop = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  auto flat = [&](const std::array<Vec3, 3>& t) {
    std::vector<std::array<double, 2>> p;
    for (const Vec3& q : t) p.push_back({q[u], q[v]});
    // Counter-clockwise, so that "left of each edge" is inside.
    const double s = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    if (s < 0) std::swap(p[1], p[2]);
    return p;
  };
  std::vector<std::array<double, 2>> poly = flat(a);
  const std::vector<std::array<double, 2>> other = flat(b);
  for (std::size_t i = 0; i < 3 && poly.size() >= 3; ++i) poly = clip(poly, other[i], other[(i + 1) % 3]);
  if (poly.size() < 3) return 0;
  // The area as a fan from the first corner: relative coordinates, so that a polygon clipped
  // down to a point (triangles that touch) has an area of its own size, not the rounding of
  // products of its absolute coordinates, which divided by its tiny perimeter would be a
  // width of a fraction of a millimetre.
  double area = 0, perimeter = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const auto& p = poly[i];
    const auto& q = poly[(i + 1) % poly.size()];
    area += (p[0] - poly[0][0]) * (q[1] - poly[0][1]) - (p[1] - poly[0][1]) * (q[0] - poly[0][0]);
    perimeter += std::hypot(q[0] - p[0], q[1] - p[1]);
  }
  // The area in the plane itself: the projection shrank it by the dropped normal component.
  area = 0.5 * std::abs(area) * norm(normal) / std::abs(normal[drop]);
  return perimeter > 0 ? 2 * area / perimeter : 0;
}

}  // namespace

bool triangles_intersect(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b, double tolerance) {
  const Vec3 na = cross(a[1] - a[0], a[2] - a[0]), nb = cross(b[1] - b[0], b[2] - b[0]);
  const double la = norm(na), lb = norm(nb);
  if (!(la > 0) || !(lb > 0)) return false;  // a degenerate triangle has no plane to cross
  double scale = 0;
  for (const auto* t : {&a, &b})
    for (const Vec3& p : *t) scale = std::max(scale, max_abs(p - a[0]));
  // Intersections shorter than floor_len are a touch. A vertex within eps of the other
  // triangle's plane lies on it (rounding). Triangles whose corners all lie within flat of
  // each other's planes, a thousandth of the tolerance, are compared in the plane, where their
  // overlap is well conditioned; the line where two nearly parallel planes meet is not
  // (rounded coordinates of a flat face would otherwise cross each other).
  const double floor_len = std::max(tolerance, 1e-9 * scale);
  const double eps = 1e-12 * scale, flat = std::max(eps, 1e-3 * floor_len);
  double da[3], db[3];
  bool coplanar = true;
  for (int i = 0; i < 3; ++i) {
    da[i] = dot(nb, a[static_cast<std::size_t>(i)] - b[0]) / lb;
    db[i] = dot(na, b[static_cast<std::size_t>(i)] - a[0]) / la;
    coplanar = coplanar && std::abs(da[i]) <= flat && std::abs(db[i]) <= flat;
    if (std::abs(da[i]) <= eps) da[i] = 0;
    if (std::abs(db[i]) <= eps) db[i] = 0;
  }
  if (coplanar) return coplanar_overlap_width(a, b, na) > floor_len;
  auto one_side = [](const double d[3]) {
    return (d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0);
  };
  if (one_side(da) || one_side(db)) return false;
  // Both meet the line where the planes meet: compare the two segments along it.
  Vec3 pa[4], pb[4];
  const int ka = plane_points(a, da, pa), kb = plane_points(b, db, pb);
  if (ka == 0 || kb == 0) return false;
  Vec3 dir = cross(na, nb);
  const double ld = norm(dir);
  if (!(ld > 0)) return false;
  dir = (1.0 / ld) * dir;
  double a0 = HUGE_VAL, a1 = -HUGE_VAL, b0 = HUGE_VAL, b1 = -HUGE_VAL;
  for (int i = 0; i < ka; ++i) {
    a0 = std::min(a0, dot(pa[i], dir));
    a1 = std::max(a1, dot(pa[i], dir));
  }
  for (int i = 0; i < kb; ++i) {
    b0 = std::min(b0, dot(pb[i], dir));
    b1 = std::max(b1, dot(pb[i], dir));
  }
  return std::min(a1, b1) - std::max(a0, b0) > floor_len;
}

namespace {

// The edge checks: open, non-manifold and misoriented edges, from the sorted uses.
void check_edges(const std::vector<SlicedMesh::Triangle>& tris, MeshCheck& r, StopPoll& stop) {
  const std::vector<EdgeUse> uses = edge_uses(tris, stop);
  for (std::size_t i = 0; i < uses.size();) {
    stop.step();
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    // Sorted by triangle within an edge: the first use names the lowest triangle.
    const int first = uses[i].triangle;
    if (j - i == 1)
      note(r.open_edges, first);
    else if (j - i > 2)
      note(r.nonmanifold_edges, first);
    else if (uses[i].forward == uses[i + 1].forward)
      note(r.misoriented_edges, first);
    i = j;
  }
}

// Triangles with the corners of an earlier one (in any order: a part exported twice, a face
// repeated): each is noted with the earlier one and marked, so that the intersection test,
// which would find every copy overlapping every other, sees only the first.
std::vector<std::uint8_t> mark_duplicates(const std::vector<SlicedMesh::Triangle>& tris, MeshDefect& d,
                                          StopPoll& stop) {
  std::vector<std::pair<std::array<int, 3>, int>> keys(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    stop.step();
    std::array<int, 3> k{tris[t][0], tris[t][1], tris[t][2]};
    std::sort(k.begin(), k.end());
    keys[t] = {k, static_cast<int>(t)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<std::uint8_t> repeat(tris.size(), 0);
  for (std::size_t i = 1; i < keys.size(); ++i) {
    stop.step();
    if (keys[i].first == keys[i - 1].first) {
      std::size_t first = i - 1;
      while (first > 0 && keys[first - 1].first == keys[i].first) --first;
      repeat[static_cast<std::size_t>(keys[i].second)] = 1;
      note(d, keys[i].second, keys[first].second);
    }
  }
  return repeat;
}

// The pairs of triangles whose boxes overlap, each tested once, within a budget of pairs looked
// at and reading the stop flag (mesh_check.h).
class PairSearch {
 public:
  PairSearch(const SlicedMesh& mesh, const MeshCheckParams& params, std::vector<std::uint8_t> skip, MeshCheck& r)
      : tris_(mesh.triangles()), verts_(mesh.vertices()), params_(params), skip_(std::move(skip)), r_(r) {
    const auto n = static_cast<std::int64_t>(tris_.size());
    budget_ =
        params.max_pair_tests > 0 ? params.max_pair_tests : std::max<std::int64_t>(std::int64_t{1} << 28, 256 * n);
  }
  void run(const Box3& box);

 private:
  struct Range {
    std::int64_t lo[3], hi[3];
  };
  // Counts one pair looked at; false once the budget is spent (the search then stops).
  bool spend() {
    if (r_.intersections_cut_short) return false;
    stop_.step();
    if (++spent_ > budget_) r_.intersections_cut_short = true;
    return !r_.intersections_cut_short;
  }
  std::array<Vec3, 3> corners(int t) const {
    const auto& tri = tris_[static_cast<std::size_t>(t)];
    return {verts_[static_cast<std::size_t>(tri[0])], verts_[static_cast<std::size_t>(tri[1])],
            verts_[static_cast<std::size_t>(tri[2])]};
  }
  bool apart(std::size_t s, std::size_t t) const {
    bool a = false;
    for (int d = 0; d < 3; ++d) a = a || boxes_[s].hi[d] < boxes_[t].lo[d] || boxes_[t].hi[d] < boxes_[s].lo[d];
    return a;
  }
  void test(int s, int t) {
    int shared = 0;
    for (int u : tris_[static_cast<std::size_t>(s)])
      for (int v : tris_[static_cast<std::size_t>(t)]) shared += u == v;
    if (shared >= 2) return;  // neighbours across an edge meet along it
    if (triangles_intersect(corners(s), corners(t), params_.intersection_tolerance))
      note(r_.self_intersections, std::min(s, t), std::max(s, t));
  }
  void grid(const Box3& box);
  void cell_pairs();
  void large_pairs();

  const std::vector<SlicedMesh::Triangle>& tris_;
  const std::vector<Vec3>& verts_;
  const MeshCheckParams& params_;
  std::vector<std::uint8_t> skip_;  // duplicates and triangles without a plane: never tested
  MeshCheck& r_;
  std::int64_t budget_ = 0, spent_ = 0;
  StopPoll stop_{params_.stop, kChecking};
  std::vector<Box3> boxes_;
  std::vector<Range> ranges_;
  std::vector<std::pair<std::uint64_t, int>> entries_;
  std::vector<std::uint8_t> large_;
};

// The grid: cells about a typical triangle's size, so that a cell holds a few triangles. A
// triangle is put in each of its cells unless it spans more than `most` of them (a big face
// beside fine detail), then it is tested against every box it overlaps instead; `most` is
// lowered until the cells' entries are at most 8 per triangle, which bounds their memory
// whatever the triangles' sizes. Which pairs are tested, and so the result, does not depend on
// `most`: every pair of overlapping boxes is tested once either way.
void PairSearch::grid(const Box3& box) {
  const std::size_t n = tris_.size();
  boxes_.assign(n, Box3{});
  std::vector<double> sizes(n);
  for (std::size_t t = 0; t < n; ++t) {
    stop_.step();
    for (int v : tris_[t]) boxes_[t].expand(verts_[static_cast<std::size_t>(v)]);
    sizes[t] = max_abs(boxes_[t].hi - boxes_[t].lo);
  }
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<std::ptrdiff_t>(n / 2), sizes.end());
  const double extent = max_abs(box.hi - box.lo);
  double cell = std::max({sizes[n / 2], extent / 1024, 1e-300});
  // At most 2^21 cells along an axis, so that a cell index fits 21 bits of a key.
  cell = std::max(cell, extent / double(1 << 20));
  auto index = [&](double x, double lo) {
    const double f = std::floor((x - lo) / cell);
    return static_cast<std::int64_t>(std::clamp(f, 0.0, double((1 << 21) - 1)));
  };
  ranges_.resize(n);
  std::vector<std::int64_t> cells(n, 0);
  for (std::size_t t = 0; t < n; ++t) {
    stop_.step();
    Range& g = ranges_[t];
    for (int d = 0; d < 3; ++d) {
      g.lo[d] = index(boxes_[t].lo[d], box.lo[d]);
      g.hi[d] = index(boxes_[t].hi[d], box.lo[d]);
    }
    if (!(area2(verts_, tris_[t]) > 0)) skip_[t] = 1;  // no plane: nothing to cross
    if (!skip_[t]) cells[t] = (g.hi[0] - g.lo[0] + 1) * (g.hi[1] - g.lo[1] + 1) * (g.hi[2] - g.lo[2] + 1);
  }
  std::int64_t most = 64;
  auto entries_at = [&](std::int64_t m) {
    std::int64_t sum = 0;
    for (std::int64_t c : cells) sum += c <= m ? c : 0;
    return sum;
  };
  while (most > 1 && entries_at(most) > 8 * static_cast<std::int64_t>(n) + 1024) most /= 2;
  large_.assign(n, 0);
  entries_.reserve(static_cast<std::size_t>(entries_at(most)));
  for (std::size_t t = 0; t < n; ++t) {
    stop_.step();
    if (skip_[t]) continue;
    if (cells[t] > most) {
      large_[t] = 1;
      continue;
    }
    const Range& g = ranges_[t];
    for (std::int64_t x = g.lo[0]; x <= g.hi[0]; ++x)
      for (std::int64_t y = g.lo[1]; y <= g.hi[1]; ++y)
        for (std::int64_t z = g.lo[2]; z <= g.hi[2]; ++z)
          entries_.push_back({static_cast<std::uint64_t>((x << 42) | (y << 21) | z), static_cast<int>(t)});
  }
  std::sort(entries_.begin(), entries_.end());
  throw_if_stopped(params_.stop, kChecking);
}

// Pairs that share a cell, each tested in the first cell (lowest x, then y, then z index) of
// the boxes' common cells.
void PairSearch::cell_pairs() {
  for (std::size_t i = 0; i < entries_.size();) {
    std::size_t j = i;
    while (j < entries_.size() && entries_[j].first == entries_[i].first) ++j;
    const std::uint64_t key = entries_[i].first;
    const std::int64_t c[3] = {static_cast<std::int64_t>(key >> 42), static_cast<std::int64_t>((key >> 21) & 0x1FFFFF),
                               static_cast<std::int64_t>(key & 0x1FFFFF)};
    for (std::size_t p = i; p < j; ++p)
      for (std::size_t q = p + 1; q < j; ++q) {
        if (!spend()) return;
        const int s = entries_[p].second, t = entries_[q].second;
        const Range &gs = ranges_[static_cast<std::size_t>(s)], &gt = ranges_[static_cast<std::size_t>(t)];
        bool first_cell = true;
        for (int d = 0; d < 3; ++d) first_cell = first_cell && std::max(gs.lo[d], gt.lo[d]) == c[d];
        if (first_cell && !apart(static_cast<std::size_t>(s), static_cast<std::size_t>(t))) test(s, t);
      }
    i = j;
  }
}

// A large triangle against every other whose box it overlaps.
void PairSearch::large_pairs() {
  for (std::size_t s = 0; s < tris_.size(); ++s) {
    stop_.step();
    if (!large_[s]) continue;
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      if (t == s || (large_[t] && t < s) || skip_[t]) continue;
      if (!spend()) return;
      if (!apart(s, t)) test(static_cast<int>(s), static_cast<int>(t));
    }
  }
}

void PairSearch::run(const Box3& box) {
  grid(box);
  cell_pairs();
  large_pairs();
}

}  // namespace

MeshCheck check_mesh(const SlicedMesh& mesh, const MeshCheckParams& params) {
  MeshCheck r;
  const auto& tris = mesh.triangles();
  // Every loop over the triangles, edges and grid entries reads the stop flag (a sort of
  // millions between them takes about a second), so that a large mesh stops when asked.
  StopPoll stop(params.stop, kChecking);
  check_edges(tris, r, stop);
  throw_if_stopped(params.stop, kChecking);
  std::vector<std::uint8_t> repeat = mark_duplicates(tris, r.duplicate_triangles, stop);
  throw_if_stopped(params.stop, kChecking);
  if (!params.self_intersections || tris.size() < 2) return r;
  PairSearch(mesh, params, std::move(repeat), r).run(mesh.bounds());
  return r;
}

std::size_t orient_consistently(const std::vector<Vec3>& vertices, std::vector<SlicedMesh::Triangle>& triangles) {
  StopPoll no_stop(nullptr, "");
  const std::vector<EdgeUse> uses = edge_uses(triangles, no_stop);
  // Neighbours across edges of exactly two triangles, with whether the two run along the edge
  // the same way (then one of them must flip for them to agree).
  std::vector<std::vector<std::pair<int, bool>>> next(triangles.size());
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 2) {
      const bool same = uses[i].forward == uses[i + 1].forward;
      next[static_cast<std::size_t>(uses[i].triangle)].push_back({uses[i + 1].triangle, same});
      next[static_cast<std::size_t>(uses[i + 1].triangle)].push_back({uses[i].triangle, same});
    }
    i = j;
  }
  std::vector<int> flip(triangles.size(), -1);
  std::vector<int> component, queue;
  std::size_t flipped = 0;
  for (std::size_t seed = 0; seed < triangles.size(); ++seed) {
    if (flip[seed] >= 0) continue;
    component.clear();
    queue.assign(1, static_cast<int>(seed));
    flip[seed] = 0;
    double area[2] = {0, 0};
    while (!queue.empty()) {
      const int t = queue.back();
      queue.pop_back();
      component.push_back(t);
      area[flip[static_cast<std::size_t>(t)]] += area2(vertices, triangles[static_cast<std::size_t>(t)]);
      for (const auto& [u, same] : next[static_cast<std::size_t>(t)]) {
        if (flip[static_cast<std::size_t>(u)] >= 0) continue;  // a conflict, if any, stays
        flip[static_cast<std::size_t>(u)] = flip[static_cast<std::size_t>(t)] ^ static_cast<int>(same);
        queue.push_back(u);
      }
    }
    // Keep the orientation most of the area has: flip the class with less.
    const int turn = area[1] > area[0] ? 0 : 1;
    for (int t : component)
      if (flip[static_cast<std::size_t>(t)] == turn) {
        std::swap(triangles[static_cast<std::size_t>(t)][1], triangles[static_cast<std::size_t>(t)][2]);
        ++flipped;
      }
  }
  return flipped;
}

}  // namespace trivox
