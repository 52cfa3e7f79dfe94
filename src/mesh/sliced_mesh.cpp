#include "trivox/mesh/sliced_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

namespace trivox {

SlicedMesh::SlicedMesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
  for (const Vec3& p : vertices_) bounds_.expand(p);
  if (triangles_.empty()) return;
  // About sqrt(n) triangles a bucket, 64 to 4096 buckets: a fine mesh is not tested whole by
  // every cut, and a triangle spanning many buckets is listed in few of them.
  const auto n = static_cast<double>(triangles_.size());
  const int nb = std::clamp(static_cast<int>(std::sqrt(n)), 64, 4096);
  z0_ = bounds_.lo.z;
  dz_ = std::max((bounds_.hi.z - bounds_.lo.z) / nb, 1e-300);
  buckets_.assign(static_cast<std::size_t>(nb), {});
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    double zlo = HUGE_VAL, zhi = -HUGE_VAL;
    for (int v : triangles_[t]) {
      zlo = std::min(zlo, vertices_[static_cast<std::size_t>(v)].z);
      zhi = std::max(zhi, vertices_[static_cast<std::size_t>(v)].z);
    }
    for (int b = bucket_of(zlo); b <= bucket_of(zhi); ++b)
      buckets_[static_cast<std::size_t>(b)].push_back(static_cast<int>(t));
  }
}

int SlicedMesh::bucket_of(double z) const noexcept {
  const double b = std::floor((z - z0_) / dz_);
  // Compared as doubles first: a height far outside the mesh must not overflow the cast.
  if (!(b > 0)) return 0;
  const int last = static_cast<int>(buckets_.size()) - 1;
  return b >= last ? last : static_cast<int>(b);
}

std::span<const int> SlicedMesh::near(double z) const {
  if (buckets_.empty() || !(z >= bounds_.lo.z && z <= bounds_.hi.z)) return {};
  return buckets_[static_cast<std::size_t>(bucket_of(z))];
}

bool SlicedMesh::cut_triangle(int t, double z, Segment2& s) const {
  int direction;
  return cut_triangle(t, z, s, direction);
}

bool SlicedMesh::cut_triangle(int t, double z, Segment2& s, int& direction) const {
  const Triangle& tri = triangles_[static_cast<std::size_t>(t)];
  Vec3 pts[2];
  int found = 0, rising_at = 1;
  for (int e = 0; e < 3; ++e) {
    int ia = tri[static_cast<std::size_t>(e)], ib = tri[static_cast<std::size_t>((e + 1) % 3)];
    // Rising: from below the plane to at or above it, in the triangle's own vertex order.
    const bool rising = vertices_[static_cast<std::size_t>(ib)].z >= z;
    if (ia > ib) std::swap(ia, ib);  // fixed order: shared edges cut identically
    const Vec3& a = vertices_[static_cast<std::size_t>(ia)];
    const Vec3& b = vertices_[static_cast<std::size_t>(ib)];
    if ((a.z >= z) == (b.z >= z)) continue;
    const double u = (z - a.z) / (b.z - a.z);
    if (found < 2) {
      pts[found] = a + u * (b - a);
      if (rising) rising_at = found;
    }
    ++found;
  }
  if (found != 2) return false;
  s = {pts[0].x, pts[0].y, pts[1].x, pts[1].y};
  direction = rising_at == 0 ? 1 : -1;
  return true;
}

void SlicedMesh::cut(double z, std::vector<Segment2>& out) const {
  out.clear();
  Segment2 s;
  for (int t : near(z))
    if (cut_triangle(t, z, s)) out.push_back(s);
}

void SlicedMesh::cut(double z, std::vector<Segment2>& out, std::vector<int>& directions) const {
  out.clear();
  directions.clear();
  Segment2 s;
  int direction;
  for (int t : near(z))
    if (cut_triangle(t, z, s, direction)) {
      out.push_back(s);
      directions.push_back(direction);
    }
}

void SlicedMesh::slab(double z0, double z1, std::vector<std::array<Vec3, 3>>& out) const {
  out.clear();
  if (buckets_.empty() || z1 < bounds_.lo.z || z0 > bounds_.hi.z) return;
  const int b0 = bucket_of(z0), b1 = bucket_of(z1);
  for (int b = b0; b <= b1; ++b)
    for (int t : buckets_[static_cast<std::size_t>(b)]) {
      const Triangle& tri = triangles_[static_cast<std::size_t>(t)];
      const Vec3& p = vertices_[static_cast<std::size_t>(tri[0])];
      const Vec3& q = vertices_[static_cast<std::size_t>(tri[1])];
      const Vec3& r = vertices_[static_cast<std::size_t>(tri[2])];
      const double lo = std::min({p.z, q.z, r.z}), hi = std::max({p.z, q.z, r.z});
      if (hi < z0 || lo > z1) continue;
      // A triangle spanning several buckets is listed in each: emit it from the first one
      // the slab and the triangle share.
      if (b != std::max(b0, bucket_of(lo))) continue;
      out.push_back({p, q, r});
    }
}

SlicedMesh SlicedMesh::mapped(const std::function<Vec3(Vec3)>& map) const {
  std::vector<Vec3> moved;
  moved.reserve(vertices_.size());
  for (const Vec3& v : vertices_) moved.push_back(map(v));
  return SlicedMesh(std::move(moved), triangles_);
}

std::size_t SlicedMesh::odd_edges() const {
  std::unordered_map<std::uint64_t, int> uses;
  uses.reserve(triangles_.size() * 2);
  for (const Triangle& t : triangles_)
    for (int e = 0; e < 3; ++e) {
      auto a = static_cast<std::uint64_t>(t[static_cast<std::size_t>(e)]);
      auto b = static_cast<std::uint64_t>(t[static_cast<std::size_t>((e + 1) % 3)]);
      if (a > b) std::swap(a, b);
      ++uses[(a << 32) | b];
    }
  std::size_t odd = 0;
  for (const auto& [edge, n] : uses) odd += static_cast<std::size_t>(n % 2);
  return odd;
}

}  // namespace trivox
