// The Bezier net's per-box work, compiled once per SIMD target: this file includes itself
// through HWY_TARGET_INCLUDE for every target Highway's foreach_target.h enables, and the
// BezierNet member functions at its end call the best target's version (docs/ARCHITECTURE.md,
// "SIMD targets"). None of this arithmetic fuses multiply-adds, so every target gives the
// same numbers.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "inverse/bezier_net_kernels.cpp"
#include <hwy/foreach_target.h>  // must precede highway.h
#include <hwy/highway.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "bezier_net.h"
#include "trivox/spline/detail/homogeneous.h"
#include "trivox/spline/knot_vector.h"

HWY_BEFORE_NAMESPACE();
namespace trivox::detail {
namespace HWY_NAMESPACE {

struct Interval {
  double lo, hi;
};
inline Interval operator-(Interval a, Interval b) { return {a.lo - b.hi, a.hi - b.lo}; }
inline Interval operator*(Interval a, Interval b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}
inline Interval divide_positive(Interval a, Interval b) {  // b.lo > 0
  return a * Interval{1.0 / b.hi, 1.0 / b.lo};
}

// A control point as a V4 (this target's copy of spline/detail/homogeneous.h's load: a
// function returning a V4 is not called across targets, whose conventions for it differ).
inline V4 load_point(const H& p) noexcept {
  V4 v;
  std::memcpy(&v, p.data(), sizeof v);
  return v;
}

// Calls fn(first, step) once per line of control points along direction d, the other two
// directions in storage order: the line's points are net.h[first + i * step], i <
// net.order[d]. Defined here, per target, so that `fn` is inlined into the target's code.
template <class Fn>
inline void for_each_line(const BezierNet& net, int d, Fn&& fn) {
  const std::size_t stride[3] = {1, static_cast<std::size_t>(net.order[0]),
                                 static_cast<std::size_t>(net.order[0]) * static_cast<std::size_t>(net.order[1])};
  const int a = d == 0 ? 1 : 0, b = d == 2 ? 1 : 2;
  for (int s = 0; s < net.order[static_cast<std::size_t>(b)]; ++s)
    for (int t = 0; t < net.order[static_cast<std::size_t>(a)]; ++t)
      fn(static_cast<std::size_t>(t) * stride[a] + static_cast<std::size_t>(s) * stride[b], stride[d]);
}

Box3 net_bounds(const BezierNet& net) {
  // Plain running minima and maxima, one per coordinate, so that the compiler can keep them
  // in vector registers (the global solver asks this of every box it visits); one loop with
  // the division and one without.
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  auto sweep = [&](auto coordinate) {
    for (const H& p : net.h)
      for (std::size_t c = 0; c < 3; ++c) {
        const double v = coordinate(p, c);
        lo[c] = v < lo[c] ? v : lo[c];
        hi[c] = v > hi[c] ? v : hi[c];
      }
  };
  if (net.polynomial)
    sweep([](const H& p, std::size_t c) { return p[c]; });
  else
    sweep([](const H& p, std::size_t c) { return p[c] / p[3]; });
  Box3 b;
  if (net.h.empty()) return b;
  b.lo = {lo[0], lo[1], lo[2]};
  b.hi = {hi[0], hi[1], hi[2]};
  return b;
}

double net_max_along(const BezierNet& net, Vec3 direction) {
  double best = -HUGE_VAL;
  for (const H& p : net.h) {
    const double along = direction.x * p[0] + direction.y * p[1] + direction.z * p[2];
    best = std::max(best, net.polynomial ? along : along / p[3]);
  }
  return best;
}

void net_halve_into(const BezierNet& net, int d, BezierNet& left, BezierNet& right) {
  for (BezierNet* half : {&left, &right}) {
    half->order = net.order;
    half->box = net.box;
    half->polynomial = net.polynomial;
    half->h.resize(net.h.size());  // no allocation when a reused net has the room
  }
  const double mid = 0.5 * (net.box.lo[d] + net.box.hi[d]);
  left.box.hi[d] = mid;
  right.box.lo[d] = mid;
  const int n = net.order[static_cast<std::size_t>(d)];
  // One line of control points along d at a time (orders are at most kMaxOrder).
  std::array<H, kMaxOrder> line;
  for_each_line(net, d, [&](std::size_t first, std::size_t step) {
    for (int i = 0; i < n; ++i) line[static_cast<std::size_t>(i)] = net.h[first + static_cast<std::size_t>(i) * step];
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

std::array<double, 3> net_extents(const BezierNet& net) {
  // The longest control polygon along each direction (Euclidean points as they are needed:
  // no division at all for polynomial nets).
  std::array<double, 3> out{};
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    for_each_line(net, d, [&](std::size_t first, std::size_t step) {
      double poly = 0.0;
      for (int i = 1; i < net.order[dd]; ++i) {
        const std::size_t q = first + static_cast<std::size_t>(i) * step;
        const Vec3 e = net.euclidean(q) - net.euclidean(q - step);
        poly += norm(e);
      }
      out[dd] = std::max(out[dd], poly);
    });
  }
  return out;
}

bool net_jacobian_bounds(const BezierNet& net, Mat3& lo, Mat3& hi, const Box3& xb) {
  // x = X / W with X, W polynomial. d x / d p = (X_p - x W_p) / W, bounded by interval
  // arithmetic over the hulls of the hodograph nets (X_p, W_p), of x (the Euclidean control
  // box) and of W (the weights).
  Interval W{HUGE_VAL, -HUGE_VAL};
  for (const H& p : net.h) W = {std::min(W.lo, p[3]), std::max(W.hi, p[3])};
  if (!(W.lo > 0)) return false;
  for (int d = 0; d < 3; ++d) {
    const int n = net.order[static_cast<std::size_t>(d)];
    // Hull of the hodograph along d: differences of neighbouring control points, scaled;
    // the running extrema of X_p, Y_p, Z_p, W_p four at a time.
    V4 dlo = {HUGE_VAL, HUGE_VAL, HUGE_VAL, HUGE_VAL}, dhi = -dlo;
    if (n == 1) {
      dlo = dhi = V4{};
    } else {
      const double scale = (n - 1) / (net.box.hi[d] - net.box.lo[d]);
      // Each line's consecutive differences.
      for_each_line(net, d, [&](std::size_t first, std::size_t step) {
        V4 previous = load_point(net.h[first]);
        for (int i = 1; i < n; ++i) {
          const V4 next = load_point(net.h[first + static_cast<std::size_t>(i) * step]);
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

}  // namespace HWY_NAMESPACE
}  // namespace trivox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace trivox::detail {

HWY_EXPORT(net_bounds);
HWY_EXPORT(net_max_along);
HWY_EXPORT(net_halve_into);
HWY_EXPORT(net_extents);
HWY_EXPORT(net_jacobian_bounds);

Box3 BezierNet::bounds() const { return HWY_DYNAMIC_DISPATCH(net_bounds)(*this); }

double BezierNet::max_along(Vec3 direction) const { return HWY_DYNAMIC_DISPATCH(net_max_along)(*this, direction); }

void BezierNet::halve_into(int d, BezierNet& left, BezierNet& right) const {
  HWY_DYNAMIC_DISPATCH(net_halve_into)(*this, d, left, right);
}

std::array<double, 3> BezierNet::extents() const { return HWY_DYNAMIC_DISPATCH(net_extents)(*this); }

bool BezierNet::jacobian_bounds(Mat3& lo, Mat3& hi, const Box3& xb) const {
  return HWY_DYNAMIC_DISPATCH(net_jacobian_bounds)(*this, lo, hi, xb);
}

}  // namespace trivox::detail
#endif  // HWY_ONCE
