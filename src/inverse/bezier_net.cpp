#include "bezier_net.h"

#include "trivox/spline/detail/homogeneous.h"
#include "trivox/spline/knot_vector.h"

#include <algorithm>
#include <cmath>

namespace trivox::detail {

namespace {

struct Interval {
  double lo, hi;
};
Interval operator-(Interval a, Interval b) { return {a.lo - b.hi, a.hi - b.lo}; }
Interval operator*(Interval a, Interval b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}
Interval divide_positive(Interval a, Interval b) {  // b.lo > 0
  return a * Interval{1.0 / b.hi, 1.0 / b.lo};
}
}  // namespace

Box3 BezierNet::bounds() const {
  // Plain running minima and maxima, one per coordinate, so that the compiler can keep them
  // in vector registers (the global solver asks this of every box it visits); one loop with
  // the division and one without.
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  auto sweep = [&](auto coordinate) {
    for (const H& p : h)
      for (std::size_t c = 0; c < 3; ++c) {
        const double v = coordinate(p, c);
        lo[c] = v < lo[c] ? v : lo[c];
        hi[c] = v > hi[c] ? v : hi[c];
      }
  };
  if (polynomial)
    sweep([](const H& p, std::size_t c) { return p[c]; });
  else
    sweep([](const H& p, std::size_t c) { return p[c] / p[3]; });
  Box3 b;
  if (h.empty()) return b;
  b.lo = {lo[0], lo[1], lo[2]};
  b.hi = {hi[0], hi[1], hi[2]};
  return b;
}

double BezierNet::max_along(Vec3 direction) const {
  double best = -HUGE_VAL;
  for (const H& p : h) {
    const double along = direction.x * p[0] + direction.y * p[1] + direction.z * p[2];
    best = std::max(best, polynomial ? along : along / p[3]);
  }
  return best;
}

std::array<BezierNet, 2> BezierNet::halve(int d) const {
  std::array<BezierNet, 2> out;
  halve_into(d, out[0], out[1]);
  return out;
}

void BezierNet::halve_into(int d, BezierNet& left, BezierNet& right) const {
  for (BezierNet* half : {&left, &right}) {
    half->order = order;
    half->box = box;
    half->polynomial = polynomial;
    half->h.resize(h.size());  // no allocation when a reused net has the room
  }
  const double mid = 0.5 * (box.lo[d] + box.hi[d]);
  left.box.hi[d] = mid;
  right.box.lo[d] = mid;
  const int n = order[static_cast<std::size_t>(d)];
  // One line of control points along d at a time (orders are at most kMaxOrder).
  std::array<H, kMaxOrder> line;
  for_each_line(d, [&](std::size_t first, std::size_t step) {
    for (int i = 0; i < n; ++i) line[static_cast<std::size_t>(i)] = h[first + static_cast<std::size_t>(i) * step];
    // de Casteljau at 1/2: after r averaging steps, line[0] is the left half's point r and
    // line[n-1-r] the right half's point n-1-r.
    for (int r = 0; r < n; ++r) {
      left.h[first + static_cast<std::size_t>(r) * step] = line[0];
      right.h[first + static_cast<std::size_t>(n - 1 - r) * step] = line[static_cast<std::size_t>(n - 1 - r)];
      for (int i = 0; i < n - 1 - r; ++i)
        for (std::size_t c = 0; c < 4; ++c)
          line[static_cast<std::size_t>(i)][c] =
              0.5 * (line[static_cast<std::size_t>(i)][c] + line[static_cast<std::size_t>(i + 1)][c]);
    }
  });
}

std::array<double, 3> BezierNet::extents() const {
  // The longest control polygon along each direction (Euclidean points as they are needed:
  // no division at all for polynomial nets).
  std::array<double, 3> out{};
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    for_each_line(d, [&](std::size_t first, std::size_t step) {
      double poly = 0.0;
      for (int i = 1; i < order[dd]; ++i) {
        const std::size_t q = first + static_cast<std::size_t>(i) * step;
        poly += norm(euclidean(q) - euclidean(q - step));
      }
      out[dd] = std::max(out[dd], poly);
    });
  }
  return out;
}

bool BezierNet::jacobian_bounds(Mat3& lo, Mat3& hi, const Box3& xb) const {
  // x = X / W with X, W polynomial. d x / d p = (X_p - x W_p) / W, bounded by interval
  // arithmetic over the hulls of the hodograph nets (X_p, W_p), of x (the Euclidean control
  // box) and of W (the weights).
  Interval W{HUGE_VAL, -HUGE_VAL};
  for (const H& p : h) W = {std::min(W.lo, p[3]), std::max(W.hi, p[3])};
  if (!(W.lo > 0)) return false;
  for (int d = 0; d < 3; ++d) {
    const int n = order[static_cast<std::size_t>(d)];
    // Hull of the hodograph along d: differences of neighbouring control points, scaled;
    // the running extrema of X_p, Y_p, Z_p, W_p four at a time.
    V4 dlo = {HUGE_VAL, HUGE_VAL, HUGE_VAL, HUGE_VAL}, dhi = -dlo;
    if (n == 1) {
      dlo = dhi = V4{};
    } else {
      const double scale = (n - 1) / (box.hi[d] - box.lo[d]);
      // Each line's consecutive differences.
      for_each_line(d, [&](std::size_t first, std::size_t step) {
        V4 previous = load(h[first]);
        for (int i = 1; i < n; ++i) {
          const V4 next = load(h[first + static_cast<std::size_t>(i) * step]);
          const V4 v = scale * (next - previous);
          dlo = v < dlo ? v : dlo;
          dhi = v > dhi ? v : dhi;
          previous = next;
        }
      });
    }
    for (int r = 0; r < 3; ++r) {
      const Interval xr{xb.lo[r], xb.hi[r]};
      const Interval num = Interval{dlo[r], dhi[r]} - xr * Interval{dlo[3], dhi[3]};
      const Interval J = divide_positive(num, W);
      lo.m[static_cast<std::size_t>(r)][static_cast<std::size_t>(d)] = J.lo;
      hi.m[static_cast<std::size_t>(r)][static_cast<std::size_t>(d)] = J.hi;
    }
  }
  return true;
}

namespace {

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
