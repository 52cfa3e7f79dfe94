#include "material/spline_coefficient_bounds.h"

#include <algorithm>
#include <array>
#include <limits>

namespace trivox::detail {

void coefficient_bounds(const TensorSpline& spline, const ParamBox& box, std::span<double> lo, std::span<double> hi) {
  const auto dim = static_cast<std::size_t>(spline.point_dim());
  std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(dim), std::numeric_limits<double>::infinity());
  std::fill(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(dim), -std::numeric_limits<double>::infinity());
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
        const auto p = spline.point(i, j, k);
        for (std::size_t q = 0; q < dim; ++q) {
          lo[q] = std::min(lo[q], p[q]);
          hi[q] = std::max(hi[q], p[q]);
        }
      }
}

}  // namespace trivox::detail
