// ShellMesh for mesh trims (shell_mesh.h): the mesh taken as it is for the even-odd rule; for
// the winding-number rule, the orientation repaired and the boundary closed by cones.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <utility>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/mesh/detail/mesh_check.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {

std::string_view to_string(InsideRule r) noexcept { return r == InsideRule::kEvenOdd ? "even-odd" : "winding-number"; }

namespace {

// The solid angle triangle (a, b, c) subtends at p, positive when p sees it clockwise (p on
// the inner side of a counter-clockwise triangle); Van Oosterom and Strackee's formula.
double solid_angle(Vec3 a, Vec3 b, Vec3 c, Vec3 p) noexcept {
  a = a - p;
  b = b - p;
  c = c - p;
  const double la = norm(a), lb = norm(b), lc = norm(c);
  const double num = dot(a, cross(b, c));
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2 * std::atan2(num, den);
}

struct DirectedEdge {
  std::uint64_t key;  // lower vertex << 32 | higher vertex
  int net;            // uses from lower to higher minus uses from higher to lower
};

// Union-find over vertex indices.
int find_root(std::vector<int>& parent, int v) {
  while (parent[static_cast<std::size_t>(v)] != v) {
    parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    v = parent[static_cast<std::size_t>(v)];
  }
  return v;
}

}  // namespace

ShellMesh::ShellMesh(const TrimShell& shell) {
  if (!shell.mesh) throw ModelError(fmt::format("{}: the shell has no mesh", shell.name));
  build_mesh_trim(*shell.mesh, shell.rule);
}

void ShellMesh::build_mesh_trim(const SlicedMesh& mesh, InsideRule rule) {
  if (mesh.empty()) throw ModelError("the mesh has no triangle");
  std::vector<Vec3> vertices = mesh.vertices();
  std::vector<SlicedMesh::Triangle> triangles = mesh.triangles();
  if (rule == InsideRule::kEvenOdd) {
    build_index(std::move(vertices), std::move(triangles));
    open_edges_ = mesh_.odd_edges();
    return;
  }
  winding_ = true;
  flipped_ = orient_consistently(vertices, triangles);
  own_triangles_ = static_cast<int>(triangles.size());

  // The boundary: every edge with its net number of uses (a closed, consistently oriented
  // mesh has none left over). Its pieces, joined through shared vertices, each get a cone.
  std::vector<DirectedEdge> uses;
  uses.reserve(triangles.size() * 3);
  for (const auto& t : triangles)
    for (std::size_t e = 0; e < 3; ++e) {
      const auto a = static_cast<std::uint32_t>(t[e]), b = static_cast<std::uint32_t>(t[(e + 1) % 3]);
      uses.push_back({(std::uint64_t{std::min(a, b)} << 32) | std::max(a, b), a < b ? 1 : -1});
    }
  std::sort(uses.begin(), uses.end(), [](const DirectedEdge& x, const DirectedEdge& y) { return x.key < y.key; });
  std::vector<DirectedEdge> boundary;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    int net = 0;
    while (j < uses.size() && uses[j].key == uses[i].key) net += uses[j++].net;
    if (net != 0) boundary.push_back({uses[i].key, net});
    i = j;
  }
  std::vector<int> parent(vertices.size());
  for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<int>(v);
  for (const DirectedEdge& e : boundary) {
    const int a = find_root(parent, static_cast<int>(e.key >> 32)),
              b = find_root(parent, static_cast<int>(e.key & 0xFFFFFFFFu));
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  // Pieces in the order of their lowest edge, so the cones come out the same every run.
  std::vector<int> piece_of_root(vertices.size(), -1);
  std::vector<std::vector<DirectedEdge>> pieces;
  for (const DirectedEdge& e : boundary) {
    const int root = find_root(parent, static_cast<int>(e.key >> 32));
    int& k = piece_of_root[static_cast<std::size_t>(root)];
    if (k < 0) {
      k = static_cast<int>(pieces.size());
      pieces.emplace_back();
    }
    pieces[static_cast<std::size_t>(k)].push_back(e);
  }
  std::vector<std::pair<int, int>> ranges;
  std::vector<std::uint8_t> seen(vertices.size(), 0);
  for (const auto& piece : pieces) {
    // The apex: the mean of the piece's vertices.
    Vec3 sum{};
    int count = 0;
    std::vector<int> touched;
    for (const DirectedEdge& e : piece)
      for (const int v : {static_cast<int>(e.key >> 32), static_cast<int>(e.key & 0xFFFFFFFFu)})
        if (!seen[static_cast<std::size_t>(v)]) {
          seen[static_cast<std::size_t>(v)] = 1;
          touched.push_back(v);
          sum = sum + vertices[static_cast<std::size_t>(v)];
          ++count;
        }
    for (int v : touched) seen[static_cast<std::size_t>(v)] = 0;
    const int apex = static_cast<int>(vertices.size());
    vertices.push_back((1.0 / count) * sum);
    const int first = static_cast<int>(triangles.size());
    // Each boundary edge a -> b (with its multiplicity) gets the triangle (b, a, apex), which
    // runs along it the other way: the edge's uses then cancel, and so do the apex's edges.
    for (const DirectedEdge& e : piece) {
      const int lo = static_cast<int>(e.key >> 32), hi = static_cast<int>(e.key & 0xFFFFFFFFu);
      const int a = e.net > 0 ? lo : hi, b = e.net > 0 ? hi : lo;
      for (int m = 0; m < std::abs(e.net); ++m) triangles.push_back({b, a, apex});
    }
    ranges.push_back({first, static_cast<int>(triangles.size())});
  }

  // Outward overall: a mesh (with its cones, a closed surface) that encloses a negative
  // volume was written inside out.
  const Vec3 origin = vertices.empty() ? Vec3{} : vertices.front();
  double volume = 0;
  for (const auto& t : triangles) {
    const Vec3 a = vertices[static_cast<std::size_t>(t[0])] - origin,
               b = vertices[static_cast<std::size_t>(t[1])] - origin,
               c = vertices[static_cast<std::size_t>(t[2])] - origin;
    volume += dot(a, cross(b, c));
  }
  if (volume < 0)
    for (auto& t : triangles) std::swap(t[1], t[2]);

  build_index(std::move(vertices), std::move(triangles));
  cones_.clear();
  for (const auto& [first, end] : ranges) cones_.push_back({first, end, {}, 0, 0});
  bound_cones();
}

void ShellMesh::bound_cones() {
  const auto& v = mesh_.vertices();
  const auto& tris = mesh_.triangles();
  Box3 all;
  all_cones_ = Cone{};
  for (Cone& c : cones_) {
    Box3 box;
    c.area = 0;
    for (int t = c.first; t < c.end; ++t) {
      const auto& tri = tris[static_cast<std::size_t>(t)];
      for (int k : tri) box.expand(v[static_cast<std::size_t>(k)]);
      const Vec3 a = v[static_cast<std::size_t>(tri[0])], b = v[static_cast<std::size_t>(tri[1])],
                 d = v[static_cast<std::size_t>(tri[2])];
      c.area += 0.5 * norm(cross(b - a, d - a));
    }
    c.centre = 0.5 * (box.lo + box.hi);
    c.radius = 0.5 * norm(box.hi - box.lo);
    all.expand(box);
    all_cones_.area += c.area;
  }
  if (!cones_.empty()) {
    all_cones_.centre = 0.5 * (all.lo + all.hi);
    all_cones_.radius = 0.5 * norm(all.hi - all.lo);
  }
}

double ShellMesh::cone_winding_number(std::size_t k, Vec3 p) const {
  const Cone& c = cones_[k];
  const auto& v = mesh_.vertices();
  double sum = 0;
  for (int t = c.first; t < c.end; ++t) {
    const auto& tri = mesh_.triangles()[static_cast<std::size_t>(t)];
    sum += solid_angle(v[static_cast<std::size_t>(tri[0])], v[static_cast<std::size_t>(tri[1])],
                       v[static_cast<std::size_t>(tri[2])], p);
  }
  return sum / (4 * std::numbers::pi);
}

namespace {

// An upper bound of |the generalized winding number| of triangles of total `area` inside the
// ball (centre, radius) at p: each subtends at most its area over the squared distance.
double share_bound(Vec3 centre, double radius, double area, Vec3 p) noexcept {
  const double d = norm(p - centre) - radius;
  return d > 0 ? area / (4 * std::numbers::pi * d * d) : HUGE_VAL;
}

}  // namespace

bool ShellMesh::winding_inside(int w, Vec3 p) const {
  // With the cones' share c below 1/2 in size, w - c >= 1/2 exactly when w >= 1.
  if (cones_.empty() || share_bound(all_cones_.centre, all_cones_.radius, all_cones_.area, p) < 0.5) return w >= 1;
  double exact = 0, slack = 0;
  for (std::size_t k = 0; k < cones_.size(); ++k) {
    const double b = share_bound(cones_[k].centre, cones_[k].radius, cones_[k].area, p);
    if (b < 1e-3)
      slack += b;
    else
      exact += cone_winding_number(k, p);
  }
  const double g = w - exact;
  if (g - slack >= 0.5) return true;
  if (g + slack < 0.5) return false;
  for (std::size_t k = 0; k < cones_.size(); ++k)
    if (share_bound(cones_[k].centre, cones_[k].radius, cones_[k].area, p) < 1e-3) exact += cone_winding_number(k, p);
  return w - exact >= 0.5;
}

double ShellMesh::generalized_winding_number(Vec3 p) const {
  const auto& v = mesh_.vertices();
  const auto& tris = mesh_.triangles();
  const std::size_t own = winding_ ? static_cast<std::size_t>(own_triangles_) : tris.size();
  double sum = 0;
  for (std::size_t t = 0; t < own; ++t)
    sum += solid_angle(v[static_cast<std::size_t>(tris[t][0])], v[static_cast<std::size_t>(tris[t][1])],
                       v[static_cast<std::size_t>(tris[t][2])], p);
  return sum / (4 * std::numbers::pi);
}

}  // namespace trivox
