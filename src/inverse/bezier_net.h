// A trivariate Bezier piece in homogeneous form, as the global solver subdivides it: the
// control net (w*x, w*y, w*z, w), u fastest, over a parameter box of the original volume.
#pragma once

#include <array>
#include <vector>

#include "trivox/math.h"

namespace trivox::detail {

struct BezierNet {
  std::array<int, 3> order{};  // control points per direction
  ParamBox box;                // the parameters of the original volume this net covers
  std::vector<std::array<double, 4>> h;
  // Every weight is exactly 1 (a polynomial volume; halving keeps it so, since it averages
  // weights): the Euclidean points are then the first three coordinates, no division needed,
  // and dividing by 1 would give the same numbers.
  bool polynomial = false;

  Vec3 euclidean(std::size_t q) const {
    const std::array<double, 4>& p = h[q];
    return polynomial ? Vec3{p[0], p[1], p[2]} : Vec3{p[0] / p[3], p[1] / p[3], p[2] / p[3]};
  }

  const std::array<double, 4>& at(int i, int j, int k) const {
    return h[static_cast<std::size_t>(i + order[0] * (j + order[1] * k))];
  }
  std::array<double, 4>& at(int i, int j, int k) {
    return h[static_cast<std::size_t>(i + order[0] * (j + order[1] * k))];
  }

  // The per-box work of the global solver below (bounds, max_along, halve_into, extents,
  // jacobian_bounds) is compiled once per SIMD target in bezier_net_kernels.cpp; each call
  // runs the best target the processor has.

  // Box of the Euclidean control points: contains the image of the net's box.
  Box3 bounds() const;

  // Largest dot(direction, P) over the Euclidean control points P. With the convex hull
  // property, dot(direction, y) for every y in the image is at most this: a plane with
  // this normal separates the image from any point beyond it.
  double max_along(Vec3 direction) const;

  // Splits at the middle of direction d (de Casteljau at 1/2, exact in homogeneous form).
  std::array<BezierNet, 2> halve(int d) const;
  // The same into two existing nets (not this one), reusing their storage.
  void halve_into(int d, BezierNet& left, BezierNet& right) const;

  // Euclidean length of the net along each direction: the longest control polygon of a
  // line along it (at least the chord, and long also for closed or bent lines), which says
  // the direction worth splitting first.
  std::array<double, 3> extents() const;

  // Conservative interval bounds of the Jacobian over the box: lo/hi of d x_r / d p_c.
  // Returns false when a weight interval reaches zero (cannot happen for valid input).
  // `euclidean_bounds` is bounds(), for a caller that has it already.
  bool jacobian_bounds(Mat3& lo, Mat3& hi) const { return jacobian_bounds(lo, hi, bounds()); }
  bool jacobian_bounds(Mat3& lo, Mat3& hi, const Box3& euclidean_bounds) const;
};

// True when the map is provably one-to-one on the net's box: with A the inverse of the
// Jacobian at the box centre (`centre_jacobian`), every matrix M in the interval Jacobian
// satisfies ||I - A M||_inf < 1, so every M is invertible and V(a) - V(b) = M (a - b) != 0
// for a != b (mean value theorem, row by row).
bool injective_on_box(const Mat3& jac_lo, const Mat3& jac_hi, const Mat3& centre_jacobian);

// What Krawczyk's operator says about the roots of V(p) = x' in `box`, for every x' within
// `tolerance` of x. With c the box centre, A the inverse of the centre Jacobian and J(box)
// the interval Jacobian, every such root p satisfies (mean value theorem, row by row)
//   p = c - A (V(c) - x') + (I - A M) (p - c)   for some M in J(box),
// so p lies in K = c - A (V(c) - x) +- (|A| tolerance + |I - A J(box)| radius). When K misses
// the box along some direction the box holds no root; otherwise, when ||I - A J(box)|| < 1,
// the map is one-to-one on it (see injective_on_box).
enum class BoxVerdict { kUndecided, kNoRoot, kInjective };
BoxVerdict krawczyk_verdict(const ParamBox& box, const Mat3& jac_lo, const Mat3& jac_hi, const Mat3& centre_jacobian,
                            Vec3 centre_value, Vec3 x, double tolerance);

}  // namespace trivox::detail
