#include "material/spline_coefficient_bounds.h"

#include "trivox/spline/refine.h"

#include <algorithm>
#include <array>
#include <limits>

namespace trivox::detail {

namespace {

// Calls f(point) for every control point whose basis function is non-zero somewhere in `box`.
template <class F>
void for_active_points(const TensorSpline& spline, const ParamBox& box, F f) {
  // Basis functions non-zero on the span holding t are span-degree .. span; over an interval
  // of parameters that is the union from the first span to the last.
  std::array<int, 3> first{0, 0, 0}, last{0, 0, 0};
  for (int d = 0; d < spline.param_dim(); ++d) {
    const KnotVector& kv = spline.knots(d);
    const double a = std::clamp(box.lo[d], kv.lo(), kv.hi());
    const double b = std::clamp(box.hi[d], kv.lo(), kv.hi());
    const auto dd = static_cast<std::size_t>(d);
    first[dd] = kv.find_span(std::min(a, b)) - kv.degree();
    last[dd] = kv.find_span(std::max(a, b));
  }
  const int pd = spline.param_dim();
  for (int c = first[2]; c <= last[2]; ++c)
    for (int b = first[1]; b <= last[1]; ++b)
      for (int a = first[0]; a <= last[0]; ++a) {
        const int i = pd > 0 ? spline.knots(0).ctrl_index(a) : 0;
        const int j = pd > 1 ? spline.knots(1).ctrl_index(b) : 0;
        const int k = pd > 2 ? spline.knots(2).ctrl_index(c) : 0;
        f(spline.point(i, j, k));
      }
}

}  // namespace

void coefficient_bounds(const TensorSpline& spline, const ParamBox& box, std::span<double> lo, std::span<double> hi) {
  const auto dim = static_cast<std::size_t>(spline.point_dim());
  std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(dim), std::numeric_limits<double>::infinity());
  std::fill(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(dim), -std::numeric_limits<double>::infinity());
  for_active_points(spline, box, [&](std::span<const double> p) {
    for (std::size_t q = 0; q < dim; ++q) {
      lo[q] = std::min(lo[q], p[q]);
      hi[q] = std::max(hi[q], p[q]);
    }
  });
}

void coefficient_sum_bounds(const TensorSpline& spline, const ParamBox& box, std::span<const double> weights,
                            double& lo, double& hi) {
  const auto dim = static_cast<std::size_t>(spline.point_dim());
  lo = std::numeric_limits<double>::infinity();
  hi = -std::numeric_limits<double>::infinity();
  for_active_points(spline, box, [&](std::span<const double> p) {
    double sum = 0.0;
    for (std::size_t q = 0; q < dim; ++q) sum += weights[q] * p[q];
    lo = std::min(lo, sum);
    hi = std::max(hi, sum);
  });
}

TensorSpline restricted_piece(const TensorSpline& spline, const ParamBox& box) {
  std::array<double, 3> lo{}, hi{};
  for (int d = 0; d < spline.param_dim(); ++d) {
    const auto dd = static_cast<std::size_t>(d);
    lo[dd] = std::clamp(std::min(box.lo[d], box.hi[d]), spline.lo(d), spline.hi(d));
    hi[dd] = std::clamp(std::max(box.lo[d], box.hi[d]), spline.lo(d), spline.hi(d));
    if (!(hi[dd] > lo[dd])) return spline;
  }
  // The whole domain needs no knots inserted.
  bool whole = true;
  for (int d = 0; d < spline.param_dim(); ++d)
    whole = whole && lo[static_cast<std::size_t>(d)] <= spline.lo(d) && hi[static_cast<std::size_t>(d)] >= spline.hi(d);
  if (whole) return spline;
  return restrict_to(spline, std::span<const double>(lo.data(), static_cast<std::size_t>(spline.param_dim())),
                     std::span<const double>(hi.data(), static_cast<std::size_t>(spline.param_dim())));
}

}  // namespace trivox::detail
