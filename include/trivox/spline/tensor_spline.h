// TensorSpline: one representation for B-spline and NURBS curves, surfaces and trivariates
// of any order and any point dimension. Geometry uses point dimension 3; a material field
// with m components uses dimension m. Bezier patches are the special case of knot vectors
// without interior knots.
//
// Storage: `points` holds the num_ctrl(0) * num_ctrl(1) * num_ctrl(2) distinct control
// points, u fastest, then v, then w, each `point_dim` Euclidean coordinates; `weights`
// holds one positive weight per control point, or is empty for a polynomial spline.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/knot_vector.h"

namespace trivox {

class TensorSpline {
 public:
  // Validates and throws ModelError naming the rule broken: 1 to 3 knot vectors, point_dim
  // >= 1, points.size() == product of num_ctrl * point_dim, weights empty or one per control
  // point, every weight > 0, every number finite.
  TensorSpline(std::vector<KnotVector> knots, int point_dim, std::vector<double> points,
               std::vector<double> weights = {});

  int param_dim() const noexcept { return static_cast<int>(knots_.size()); }
  int point_dim() const noexcept { return point_dim_; }
  bool is_rational() const noexcept { return !weights_.empty(); }
  const KnotVector& knots(int dir) const { return knots_.at(static_cast<std::size_t>(dir)); }
  const std::vector<KnotVector>& all_knots() const noexcept { return knots_; }
  // Distinct control points along `dir` (1 for a direction beyond param_dim).
  int num_ctrl(int dir) const noexcept {
    return dir < param_dim() ? knots_[static_cast<std::size_t>(dir)].num_ctrl() : 1;
  }
  int total_ctrl() const noexcept { return num_ctrl(0) * num_ctrl(1) * num_ctrl(2); }
  std::span<const double> points() const noexcept { return points_; }
  std::span<const double> weights() const noexcept { return weights_; }
  // Linear index of control point (i, j, k), u fastest.
  int ctrl_linear(int i, int j, int k) const noexcept { return i + num_ctrl(0) * (j + num_ctrl(1) * k); }
  std::span<const double> point(int i, int j = 0, int k = 0) const noexcept {
    return std::span<const double>(points_).subspan(
        static_cast<std::size_t>(ctrl_linear(i, j, k)) * static_cast<std::size_t>(point_dim_),
        static_cast<std::size_t>(point_dim_));
  }
  double weight(int i, int j = 0, int k = 0) const noexcept {
    return weights_.empty() ? 1.0 : weights_[static_cast<std::size_t>(ctrl_linear(i, j, k))];
  }

  // Parametric domain along `dir`.
  double lo(int dir) const { return knots(dir).lo(); }
  double hi(int dir) const { return knots(dir).hi(); }

  // Value at parameter `t` (param_dim values; clamped to the domain): writes point_dim values.
  // General path for any dimensions; allocation-free.
  void evaluate(std::span<const double> t, std::span<double> out) const;

  // Value and first partial derivatives: `value` gets point_dim values, `partials` gets
  // param_dim * point_dim values, partials[d * point_dim + c] = d(out_c)/d(t_d).
  void evaluate_with_partials(std::span<const double> t, std::span<double> value, std::span<double> partials) const;

  // Conservative bounds (first 3 coordinates) of the image of the whole spline: the box of
  // its Euclidean control points.
  Box3 control_box() const;

  // The same spline with its control points transformed by f (point_dim values in place).
  template <class F>
  TensorSpline transformed(F&& f) const {
    TensorSpline copy = *this;
    for (std::size_t p = 0; p < copy.points_.size(); p += static_cast<std::size_t>(point_dim_))
      f(std::span<double>(copy.points_).subspan(p, static_cast<std::size_t>(point_dim_)));
    copy.validate();
    return copy;
  }

 private:
  void validate() const;

  std::vector<KnotVector> knots_;
  int point_dim_ = 3;
  std::vector<double> points_;
  std::vector<double> weights_;
};

}  // namespace trivox
