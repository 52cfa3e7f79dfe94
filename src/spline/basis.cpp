#include "trivox/spline/detail/basis.h"

#include <array>

namespace trivox {

// The NURBS Book, Algorithm A2.2 (with degree p = k - 1).
namespace {
// A2.2 up to degree `p` (which may be below the knot vector's degree).
inline void basis_to_degree(const KnotVector& kv, int span, double t, int p, double* out) noexcept {
  // Uninitialised on purpose: entries are written before they are read, and clearing
  // 2 * kMaxOrder doubles per call would dominate evaluation time.
  std::array<double, kMaxOrder + 1> left, right;
  out[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[static_cast<std::size_t>(j)] = t - kv[span + 1 - j];
    right[static_cast<std::size_t>(j)] = kv[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double denom = right[static_cast<std::size_t>(r + 1)] + left[static_cast<std::size_t>(j - r)];
      const double temp = out[r] / denom;
      out[r] = saved + right[static_cast<std::size_t>(r + 1)] * temp;
      saved = left[static_cast<std::size_t>(j - r)] * temp;
    }
    out[j] = saved;
  }
}
}  // namespace

void basis_functions(const KnotVector& kv, int span, double t, double* out) noexcept {
  basis_to_degree(kv, span, t, kv.degree(), out);
}

void basis_first_derivatives(const KnotVector& kv, int span, double t, double* values, double* derivs) noexcept {
  const int p = kv.degree();
  if (p == 0) {
    values[0] = 1.0;
    derivs[0] = 0.0;
    return;
  }
  std::array<double, kMaxOrder> lower;  // N_{s-p+1+q, p-1}, q = 0..p-1
  basis_to_degree(kv, span, t, p - 1, lower.data());
  for (int r = 0; r <= p; ++r) {
    const int i = span - p + r;
    const double a = r > 0 ? lower[static_cast<std::size_t>(r - 1)] / (kv[i + p] - kv[i]) : 0.0;
    const double b = r < p ? lower[static_cast<std::size_t>(r)] / (kv[i + p + 1] - kv[i + 1]) : 0.0;
    // Degree p from degree p - 1 (Cox-de Boor) and its derivative from the same terms.
    values[r] = (t - kv[i]) * a + (kv[i + p + 1] - t) * b;
    derivs[r] = p * (a - b);
  }
}

// The NURBS Book, Algorithm A2.3.
void basis_derivatives(const KnotVector& kv, int span, double t, int n, double* ders) noexcept {
  const int p = kv.degree();
  const int k = p + 1;
  // ndu[j][r]: basis values (upper triangle) and knot differences (lower triangle).
  std::array<std::array<double, kMaxOrder>, kMaxOrder> ndu{};
  std::array<double, kMaxOrder> left{}, right{};
  std::array<std::array<double, kMaxOrder>, 2> a{};
  auto at = [](auto& arr, int i) -> auto& { return arr[static_cast<std::size_t>(i)]; };

  at(ndu, 0)[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    at(left, j) = t - kv[span + 1 - j];
    at(right, j) = kv[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      at(at(ndu, j), r) = at(right, r + 1) + at(left, j - r);
      const double temp = at(at(ndu, r), j - 1) / at(at(ndu, j), r);
      at(at(ndu, r), j) = saved + at(right, r + 1) * temp;
      saved = at(left, j - r) * temp;
    }
    at(at(ndu, j), j) = saved;
  }
  for (int j = 0; j <= p; ++j) ders[j] = at(at(ndu, j), p);
  for (int d = 1; d <= n; ++d)
    for (int j = 0; j <= p; ++j) ders[d * k + j] = 0.0;

  const int nd = n < p ? n : p;
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    at(a, 0)[0] = 1.0;
    for (int d = 1; d <= nd; ++d) {
      double v = 0.0;
      const int rk = r - d, pk = p - d;
      if (r >= d) {
        at(at(a, s2), 0) = at(at(a, s1), 0) / at(at(ndu, pk + 1), rk);
        v = at(at(a, s2), 0) * at(at(ndu, rk), pk);
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? d - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        at(at(a, s2), j) = (at(at(a, s1), j) - at(at(a, s1), j - 1)) / at(at(ndu, pk + 1), rk + j);
        v += at(at(a, s2), j) * at(at(ndu, rk + j), pk);
      }
      if (r <= pk) {
        at(at(a, s2), d) = -at(at(a, s1), d - 1) / at(at(ndu, pk + 1), r);
        v += at(at(a, s2), d) * at(at(ndu, r), pk);
      }
      ders[d * k + r] = v;
      std::swap(s1, s2);
    }
  }
  double factor = p;
  for (int d = 1; d <= nd; ++d) {
    for (int j = 0; j <= p; ++j) ders[d * k + j] *= factor;
    factor *= (p - d);
  }
}

}  // namespace trivox
