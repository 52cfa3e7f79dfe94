// Fixtures for the trimming tests: hexahedra as volumes and as closed shells of bilinear
// faces, and an independent point-in-solid test (the generalized winding number).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "trivox/spline/volume.h"
#include "trivox/trim/trim.h"

namespace trivox::test {

// Corner (i, j, k) of a hexahedron, i, j, k in {0, 1}, is c[i + 2j + 4k].
using Hexahedron = std::array<Vec3, 8>;

inline Volume hexahedron_volume(const Hexahedron& c) {
  std::vector<double> pts;
  for (const Vec3& p : c) pts.insert(pts.end(), {p.x, p.y, p.z});
  return Volume(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts));
}

inline TensorSpline bilinear_surface(Vec3 p00, Vec3 p10, Vec3 p01, Vec3 p11) {
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2)}, 3,
                      {p00.x, p00.y, p00.z, p10.x, p10.y, p10.z, p01.x, p01.y, p01.z, p11.x, p11.y, p11.z});
}

// The six faces of a hexahedron as bilinear surfaces, normals (d/du x d/dv) outward for a
// right-handed hexahedron (optionally leaving one out).
inline TrimShell hexahedron_shell(const Hexahedron& c, int leave_out = -1) {
  TrimShell s;
  s.name = "hexahedron";
  auto at = [&](int i, int j, int k) { return c[static_cast<std::size_t>(i + 2 * j + 4 * k)]; };
  const std::array<TensorSpline, 6> faces = {bilinear_surface(at(0, 0, 0), at(0, 0, 1), at(0, 1, 0), at(0, 1, 1)),
                                             bilinear_surface(at(1, 0, 0), at(1, 1, 0), at(1, 0, 1), at(1, 1, 1)),
                                             bilinear_surface(at(0, 0, 0), at(1, 0, 0), at(0, 0, 1), at(1, 0, 1)),
                                             bilinear_surface(at(0, 1, 0), at(0, 1, 1), at(1, 1, 0), at(1, 1, 1)),
                                             bilinear_surface(at(0, 0, 0), at(0, 1, 0), at(1, 0, 0), at(1, 1, 0)),
                                             bilinear_surface(at(0, 0, 1), at(1, 0, 1), at(0, 1, 1), at(1, 1, 1))};
  for (int f = 0; f < 6; ++f)
    if (f != leave_out) s.surfaces.push_back(faces[static_cast<std::size_t>(f)]);
  return s;
}

inline Hexahedron axis_box(Vec3 lo, Vec3 hi) {
  Hexahedron c;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        c[static_cast<std::size_t>(i + 2 * j + 4 * k)] = {i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z};
  return c;
}

// An independent triangle soup of a shell: every surface sampled on its own n x n grid, no
// welding. Its generalized winding number (the sum of the solid angles of the triangles,
// Van Oosterom and Strackee 1983, over 4 pi) is about +-1 inside and 0 outside for consistently
// oriented faces, and tolerates the hairline gaps of an unwelded soup.
struct TriangleSoup {
  std::vector<std::array<Vec3, 3>> triangles;

  TriangleSoup(const TrimShell& shell, int n) {
    for (const TensorSpline& s : shell.surfaces) {
      auto eval = [&](int i, int j) {
        const double t[2] = {s.lo(0) + (s.hi(0) - s.lo(0)) * i / (n - 1), s.lo(1) + (s.hi(1) - s.lo(1)) * j / (n - 1)};
        double p[3];
        s.evaluate(t, p);
        return Vec3{p[0], p[1], p[2]};
      };
      std::vector<Vec3> grid;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) grid.push_back(eval(i, j));
      auto g = [&](int i, int j) { return grid[static_cast<std::size_t>(j * n + i)]; };
      for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
          triangles.push_back({g(i, j), g(i + 1, j), g(i + 1, j + 1)});
          triangles.push_back({g(i, j), g(i + 1, j + 1), g(i, j + 1)});
        }
    }
  }

  double winding(Vec3 p) const {
    double sum = 0;
    for (const auto& t : triangles) {
      const Vec3 a = t[0] - p, b = t[1] - p, c = t[2] - p;
      const double la = norm(a), lb = norm(b), lc = norm(c);
      const double num = dot(a, cross(b, c));
      const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
      sum += 2.0 * std::atan2(num, den);
    }
    return sum / (4.0 * std::numbers::pi);
  }
  bool inside(Vec3 p) const { return std::abs(winding(p)) > 0.5; }
};

// An independent point-in-solid test by vertical rays, a method the slicer does not use (it
// casts rays along +x within each layer's plane): the heights where the vertical line
// through (x, y) crosses a triangle soup, found through a grid of xy buckets. A closed
// surface is crossed an even number of times; a line through a hairline gap of the soup
// (or exactly through an edge) is crossed an odd number of times, and the caller moves it by
// a hair. A point is inside when an odd number of crossings lie above it.
class VerticalRays {
 public:
  explicit VerticalRays(std::vector<std::array<Vec3, 3>> triangles) : triangles_(std::move(triangles)) {
    for (const auto& t : triangles_)
      for (const Vec3& p : t) {
        lo_x_ = std::min(lo_x_, p.x);
        hi_x_ = std::max(hi_x_, p.x);
        lo_y_ = std::min(lo_y_, p.y);
        hi_y_ = std::max(hi_y_, p.y);
      }
    n_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(triangles_.size()) / 4.0)), 1, 2048);
    cells_.resize(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_));
    for (std::size_t k = 0; k < triangles_.size(); ++k) {
      const auto& t = triangles_[k];
      const int i0 = cell(std::min({t[0].x, t[1].x, t[2].x}), lo_x_, hi_x_);
      const int i1 = cell(std::max({t[0].x, t[1].x, t[2].x}), lo_x_, hi_x_);
      const int j0 = cell(std::min({t[0].y, t[1].y, t[2].y}), lo_y_, hi_y_);
      const int j1 = cell(std::max({t[0].y, t[1].y, t[2].y}), lo_y_, hi_y_);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) cells_[static_cast<std::size_t>(j * n_ + i)].push_back(static_cast<int>(k));
    }
  }

  // The sorted heights of the crossings; false when their count is odd.
  bool crossings(double x, double y, std::vector<double>& zs) const {
    zs.clear();
    if (x < lo_x_ || x > hi_x_ || y < lo_y_ || y > hi_y_) return true;
    for (int k : cells_[static_cast<std::size_t>(cell(y, lo_y_, hi_y_) * n_ + cell(x, lo_x_, hi_x_))]) {
      const auto& t = triangles_[static_cast<std::size_t>(k)];
      auto edge = [&](const Vec3& a, const Vec3& b) { return (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x); };
      const double e0 = edge(t[1], t[2]), e1 = edge(t[2], t[0]), e2 = edge(t[0], t[1]);
      const bool pos = e0 > 0 && e1 > 0 && e2 > 0, neg = e0 < 0 && e1 < 0 && e2 < 0;
      if (!pos && !neg) continue;
      const double sum = e0 + e1 + e2;
      zs.push_back((e0 * t[0].z + e1 * t[1].z + e2 * t[2].z) / sum);
    }
    std::sort(zs.begin(), zs.end());
    return zs.size() % 2 == 0;
  }

  static bool inside(const std::vector<double>& zs, double z) {
    return (zs.end() - std::upper_bound(zs.begin(), zs.end(), z)) % 2 == 1;
  }

 private:
  int cell(double v, double lo, double hi) const {
    return std::clamp(static_cast<int>((v - lo) / (hi - lo) * n_), 0, n_ - 1);
  }
  std::vector<std::array<Vec3, 3>> triangles_;
  double lo_x_ = 1e300, hi_x_ = -1e300, lo_y_ = 1e300, hi_y_ = -1e300;
  int n_ = 1;
  std::vector<std::vector<int>> cells_;
};

}  // namespace trivox::test
