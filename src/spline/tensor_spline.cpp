#include "trivox/spline/tensor_spline.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/limits.h"
#include "trivox/spline/detail/basis.h"

namespace trivox {

TensorSpline::TensorSpline(std::vector<KnotVector> knots, int point_dim, std::vector<double> points,
                           std::vector<double> weights)
    : knots_(std::move(knots)), point_dim_(point_dim), points_(std::move(points)), weights_(std::move(weights)) {
  validate();
}

void TensorSpline::validate() const {
  if (knots_.empty() || knots_.size() > 3)
    throw ModelError(fmt::format("a tensor spline has 1 to 3 parametric directions, got {}", knots_.size()));
  if (point_dim_ < 1) throw ModelError(fmt::format("point dimension must be at least 1, got {}", point_dim_));
  // The count of control points, checked before total_ctrl() (an int product) is trusted.
  std::int64_t count = 1;
  for (const KnotVector& kv : knots_) {
    const auto next = product_within(count, kv.num_ctrl(), kMaxControlPoints);
    if (!next)
      throw ModelError(fmt::format("the knot vectors give more than {} control points (the limit of one spline)",
                                   kMaxControlPoints));
    count = *next;
  }
  const auto n = static_cast<std::size_t>(count);
  if (points_.size() != n * static_cast<std::size_t>(point_dim_))
    throw ModelError(fmt::format("expected {} control points of dimension {} ({} numbers), got {} numbers", n,
                                 point_dim_, n * static_cast<std::size_t>(point_dim_), points_.size()));
  if (!weights_.empty() && weights_.size() != n)
    throw ModelError(fmt::format("expected {} weights (one per control point), got {}", n, weights_.size()));
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (!std::isfinite(points_[i]))
      throw ModelError(fmt::format("control point {} has a coordinate that is not a finite number",
                                   i / static_cast<std::size_t>(point_dim_)));
  for (std::size_t i = 0; i < weights_.size(); ++i)
    if (!std::isfinite(weights_[i]) || !(weights_[i] > 0.0))
      throw ModelError(fmt::format("weight of control point {} is {}; weights must be finite and > 0", i, weights_[i]));
  if (!weights_.empty()) {
    const auto [lightest, heaviest] = std::minmax_element(weights_.begin(), weights_.end());
    if (*heaviest / *lightest > kMaxWeightRatio)
      throw ModelError(
          fmt::format("weights range from {} (control point {}) to {} (control point {}), a ratio of {:.3g}; the ratio "
                      "may be at most {:.0e}: beyond it the weights squeeze the cell's parameters into a slab thinner "
                      "than double precision resolves",
                      *lightest, lightest - weights_.begin(), *heaviest, heaviest - weights_.begin(),
                      *heaviest / *lightest, kMaxWeightRatio));
  }
  // Rational splines are evaluated (and written to .itd) in homogeneous form, w * x: that
  // product must be a finite double too. (What a model file may hold is the readers' rule:
  // io_detail::rational_numbers_problem.)
  for (std::size_t i = 0; i < weights_.size(); ++i)
    for (int c = 0; c < point_dim_; ++c) {
      const double p = points_[i * static_cast<std::size_t>(point_dim_) + static_cast<std::size_t>(c)];
      if (!std::isfinite(weights_[i] * p))
        throw ModelError(
            fmt::format("control point {}: weight {} times coordinate {} overflows; the weighted "
                        "coordinates of a rational spline must be finite numbers",
                        i, weights_[i], p));
    }
}

namespace {

// Per-direction basis values (and first derivatives) at one parameter; directions beyond
// the spline's parametric dimension hold the single constant function 1.
struct DirectionBasis {
  int first = 0;  // first basis index
  int count = 1;  // number of non-zero functions
  // [0..count) values, [count..2count) derivatives; an unused direction holds N = 1, N' = 0.
  std::array<double, 2 * kMaxOrder> ders{1.0};

  void compute(const KnotVector& kv, double t, bool with_derivative) {
    const int span = kv.find_span(t);
    const double tc = std::clamp(t, kv.lo(), kv.hi());
    count = kv.order();
    first = span - kv.degree();
    if (with_derivative)
      basis_first_derivatives(kv, span, tc, ders.data(), ders.data() + count);
    else
      basis_functions(kv, span, tc, ders.data());
  }
  double value(int j) const { return ders[static_cast<std::size_t>(j)]; }
  double derivative(int j) const { return ders[static_cast<std::size_t>(count + j)]; }
};

}  // namespace

void TensorSpline::evaluate(std::span<const double> t, std::span<double> out) const {
  std::array<DirectionBasis, 3> b;
  for (int d = 0; d < param_dim(); ++d)
    b[static_cast<std::size_t>(d)].compute(knots_[static_cast<std::size_t>(d)], t[static_cast<std::size_t>(d)], false);
  const auto dim = static_cast<std::size_t>(point_dim_);
  std::fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(dim), 0.0);
  double wsum = 0.0;
  for (int c = 0; c < b[2].count; ++c)
    for (int bj = 0; bj < b[1].count; ++bj)
      for (int a = 0; a < b[0].count; ++a) {
        const int i = param_dim() > 0 ? knots_[0].ctrl_index(b[0].first + a) : 0;
        const int j = param_dim() > 1 ? knots_[1].ctrl_index(b[1].first + bj) : 0;
        const int k = param_dim() > 2 ? knots_[2].ctrl_index(b[2].first + c) : 0;
        const double bw = b[0].value(a) * b[1].value(bj) * b[2].value(c) * weight(i, j, k);
        const auto p = point(i, j, k);
        for (std::size_t q = 0; q < dim; ++q) out[q] += bw * p[q];
        wsum += bw;
      }
  if (is_rational())
    for (std::size_t q = 0; q < dim; ++q) out[q] /= wsum;
}

void TensorSpline::evaluate_with_partials(std::span<const double> t, std::span<double> value,
                                          std::span<double> partials) const {
  const int pd = param_dim();
  std::array<DirectionBasis, 3> b;
  for (int d = 0; d < pd; ++d)
    b[static_cast<std::size_t>(d)].compute(knots_[static_cast<std::size_t>(d)], t[static_cast<std::size_t>(d)], true);
  const auto dim = static_cast<std::size_t>(point_dim_);
  std::fill(value.begin(), value.begin() + static_cast<std::ptrdiff_t>(dim), 0.0);
  std::fill(partials.begin(), partials.begin() + static_cast<std::ptrdiff_t>(dim) * pd, 0.0);
  double wsum = 0.0;
  std::array<double, 3> wd{};
  for (int c = 0; c < b[2].count; ++c)
    for (int bj = 0; bj < b[1].count; ++bj)
      for (int a = 0; a < b[0].count; ++a) {
        const int i = pd > 0 ? knots_[0].ctrl_index(b[0].first + a) : 0;
        const int j = pd > 1 ? knots_[1].ctrl_index(b[1].first + bj) : 0;
        const int k = pd > 2 ? knots_[2].ctrl_index(b[2].first + c) : 0;
        const double w = weight(i, j, k);
        const double nu = b[0].value(a), nv = b[1].value(bj), nw = b[2].value(c);
        const double bw = nu * nv * nw * w;
        // Derivatives of the tensor basis, one per parametric direction.
        const std::array<double, 3> dbw = {pd > 0 ? b[0].derivative(a) * nv * nw * w : 0.0,
                                           pd > 1 ? nu * b[1].derivative(bj) * nw * w : 0.0,
                                           pd > 2 ? nu * nv * b[2].derivative(c) * w : 0.0};
        const auto p = point(i, j, k);
        for (std::size_t q = 0; q < dim; ++q) value[q] += bw * p[q];
        wsum += bw;
        for (int d = 0; d < pd; ++d) {
          const double db = dbw[static_cast<std::size_t>(d)];
          for (std::size_t q = 0; q < dim; ++q) partials[static_cast<std::size_t>(d) * dim + q] += db * p[q];
          wd[static_cast<std::size_t>(d)] += db;
        }
      }
  if (!is_rational()) return;
  // Quotient rule: x = A / W, dx = (dA - x dW) / W.
  for (std::size_t q = 0; q < dim; ++q) value[q] /= wsum;
  for (int d = 0; d < pd; ++d)
    for (std::size_t q = 0; q < dim; ++q) {
      double& pq = partials[static_cast<std::size_t>(d) * dim + q];
      pq = (pq - value[q] * wd[static_cast<std::size_t>(d)]) / wsum;
    }
}

Box3 TensorSpline::control_box() const {
  Box3 box;
  const auto dim = static_cast<std::size_t>(point_dim_);
  for (std::size_t p = 0; p < points_.size(); p += dim)
    box.expand(Vec3{points_[p], dim > 1 ? points_[p + 1] : 0.0, dim > 2 ? points_[p + 2] : 0.0});
  return box;
}

}  // namespace trivox
