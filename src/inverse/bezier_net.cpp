#include "bezier_net.h"

#include <algorithm>
#include <cmath>

namespace trivox::detail {

std::array<BezierNet, 2> BezierNet::halve(int d) const {
  std::array<BezierNet, 2> out;
  halve_into(d, out[0], out[1]);
  return out;
}

namespace {

struct Interval {
  double lo, hi;
};

// A = inverse of C (adjugate / det); false when C is singular.
bool invert3(const Mat3& C, Mat3& A) {
  const double det = C.determinant();
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      A.m[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
          (C.m[static_cast<std::size_t>(i1)][static_cast<std::size_t>(j1)] *
               C.m[static_cast<std::size_t>(i2)][static_cast<std::size_t>(j2)] -
           C.m[static_cast<std::size_t>(i1)][static_cast<std::size_t>(j2)] *
               C.m[static_cast<std::size_t>(i2)][static_cast<std::size_t>(j1)]) /
          det;
    }
  return true;
}

// |I - A M| entrywise at its worst over the interval matrix M = [lo, hi].
Mat3 contraction_bound(const Mat3& A, const Mat3& jac_lo, const Mat3& jac_hi) {
  Mat3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Interval s{0.0, 0.0};
      for (int k = 0; k < 3; ++k) {
        const double a = A.m[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
        const double l = jac_lo.m[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)];
        const double h = jac_hi.m[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)];
        s.lo += std::min(a * l, a * h);
        s.hi += std::max(a * l, a * h);
      }
      const double delta = i == j ? 1.0 : 0.0;
      out.m[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
          std::max(std::abs(delta - s.lo), std::abs(delta - s.hi));
    }
  return out;
}

double max_row_sum(const Mat3& m) {
  double worst = 0.0;
  for (const auto& row : m.m) worst = std::max(worst, row[0] + row[1] + row[2]);
  return worst;
}

}  // namespace

bool injective_on_box(const Mat3& jac_lo, const Mat3& jac_hi, const Mat3& centre_jacobian) {
  Mat3 A;
  if (!invert3(centre_jacobian, A)) return false;
  return max_row_sum(contraction_bound(A, jac_lo, jac_hi)) < 1.0;
}

BoxVerdict krawczyk_verdict(const ParamBox& box, const Mat3& jac_lo, const Mat3& jac_hi, const Mat3& centre_jacobian,
                            Vec3 centre_value, Vec3 x, double tolerance) {
  Mat3 A;
  if (!invert3(centre_jacobian, A)) return BoxVerdict::kUndecided;
  const Mat3 m = contraction_bound(A, jac_lo, jac_hi);
  const Vec3 c = box.center(), radius = 0.5 * box.size();
  const Vec3 k = c - A * (centre_value - x);
  for (int i = 0; i < 3; ++i) {
    const auto r = static_cast<std::size_t>(i);
    double e = 0.0;
    for (int j = 0; j < 3; ++j) {
      const auto col = static_cast<std::size_t>(j);
      e += m.m[r][col] * radius[j] + std::abs(A.m[r][col]) * tolerance;
    }
    // Rounding in V(c), A and the sums above: a margin far above it, far below a box.
    e += 1e-9 * (radius[i] + std::abs(c[i])) + 1e-9 * std::abs(k[i] - c[i]);
    if (!std::isfinite(k[i]) || !std::isfinite(e)) return BoxVerdict::kUndecided;
    if (k[i] + e < box.lo[i] || k[i] - e > box.hi[i]) return BoxVerdict::kNoRoot;
  }
  return max_row_sum(m) < 1.0 ? BoxVerdict::kInjective : BoxVerdict::kUndecided;
}

}  // namespace trivox::detail
