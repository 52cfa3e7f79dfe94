// Small fixed-size value types shared by the kernel: 3-vectors, 3x3 matrices, boxes.
// Model-space quantities are in model units (millimetres in a scene); parameters are in the
// spline's own parametric units.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace trivox {

struct Vec3 {
  double x = 0, y = 0, z = 0;

  constexpr double& operator[](int i) noexcept { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr double operator[](int i) const noexcept { return i == 0 ? x : (i == 1 ? y : z); }
  friend constexpr Vec3 operator+(Vec3 a, Vec3 b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3 operator-(Vec3 a, Vec3 b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3 operator*(double s, Vec3 a) noexcept { return {s * a.x, s * a.y, s * a.z}; }
  friend constexpr bool operator==(Vec3, Vec3) = default;
};

inline double dot(Vec3 a, Vec3 b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(Vec3 a) noexcept { return std::sqrt(dot(a, a)); }
inline double max_abs(Vec3 a) noexcept { return std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)}); }

// Row-major 3x3 matrix. As a Jacobian of V(u,v,w): column c is dV/d(param c), i.e.
// m[r][c] = d V_r / d p_c.
struct Mat3 {
  std::array<std::array<double, 3>, 3> m{};

  Vec3 column(int c) const noexcept { return {m[0][c], m[1][c], m[2][c]}; }
  Vec3 operator*(Vec3 v) const noexcept {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  double determinant() const noexcept { return dot(column(0), cross(column(1), column(2))); }
};

// Solves J d = r by Cramer's rule. Returns false (and leaves d alone) when |det J| is not
// above `min_abs_det`, so a singular Jacobian is an outcome the caller sees.
inline bool solve3(const Mat3& J, Vec3 r, Vec3& d, double min_abs_det) noexcept {
  const Vec3 c0 = J.column(0), c1 = J.column(1), c2 = J.column(2);
  const Vec3 c12 = cross(c1, c2);
  const double det = dot(c0, c12);
  if (!(std::abs(det) > min_abs_det)) return false;
  const double inv = 1.0 / det;
  d = {dot(r, c12) * inv, dot(c0, cross(r, c2)) * inv, dot(c0, cross(c1, r)) * inv};
  return true;
}

// J^-1 by the adjugate. Returns false (and leaves inv alone) when |det J| is not above
// `min_abs_det`.
inline bool invert3(const Mat3& J, Mat3& inv, double min_abs_det) noexcept {
  const Vec3 c0 = J.column(0), c1 = J.column(1), c2 = J.column(2);
  const Vec3 r0 = cross(c1, c2), r1 = cross(c2, c0), r2 = cross(c0, c1);
  const double det = dot(c0, r0);
  if (!(std::abs(det) > min_abs_det)) return false;
  const double k = 1.0 / det;
  inv.m = {{{r0.x * k, r0.y * k, r0.z * k}, {r1.x * k, r1.y * k, r1.z * k}, {r2.x * k, r2.y * k, r2.z * k}}};
  return true;
}

// Axis-aligned box in model space; empty when lo > hi in any axis.
struct Box3 {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity()};

  bool empty() const noexcept { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void expand(Vec3 p) noexcept {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  void expand(const Box3& b) noexcept {
    if (!b.empty()) {
      expand(b.lo);
      expand(b.hi);
    }
  }
  Vec3 size() const noexcept { return hi - lo; }
  double diagonal() const noexcept { return empty() ? 0.0 : norm(size()); }
  bool contains(Vec3 p, double tol = 0.0) const noexcept {
    return p.x >= lo.x - tol && p.x <= hi.x + tol && p.y >= lo.y - tol && p.y <= hi.y + tol && p.z >= lo.z - tol &&
           p.z <= hi.z + tol;
  }
};

// Box in a trivariate's parameter space: [lo[d], hi[d]] per direction d (0 = u, 1 = v, 2 = w).
struct ParamBox {
  Vec3 lo, hi;

  bool contains(Vec3 p, double tol = 0.0) const noexcept {
    return p.x >= lo.x - tol && p.x <= hi.x + tol && p.y >= lo.y - tol && p.y <= hi.y + tol && p.z >= lo.z - tol &&
           p.z <= hi.z + tol;
  }
  Vec3 clamp(Vec3 p) const noexcept {
    return {std::clamp(p.x, lo.x, hi.x), std::clamp(p.y, lo.y, hi.y), std::clamp(p.z, lo.z, hi.z)};
  }
  Vec3 center() const noexcept { return 0.5 * (lo + hi); }
  Vec3 size() const noexcept { return hi - lo; }
};

}  // namespace trivox
