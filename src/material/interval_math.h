// Interval arithmetic for the enclosures of material functions (fraction_enclosure.h):
// every operation rounds outwards, so that an interval holds the exact result and every
// result the same operations give in floating point from values inside their operands'
// intervals. Elementary functions from the C library are widened by a few units in the last
// place, more than their documented error. A value that may not be a finite number (NaN, or
// infinite) is marked `nan`.
#pragma once

#include <cmath>
#include <limits>

#include "trivox/material/fraction_enclosure.h"

namespace trivox::detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// An interval value of an expression: `nan` when some point may give NaN (then lo and hi
// mean nothing).
struct IV {
  double lo = 0.0, hi = 0.0;
  bool nan = false;

  static IV point(double x) noexcept { return std::isnan(x) ? IV{-kInf, kInf, true} : IV{x, x, false}; }
  static IV undefined() noexcept { return {-kInf, kInf, true}; }
  bool finite() const noexcept { return !nan && lo > -kInf && hi < kInf; }
  bool is_point() const noexcept { return !nan && lo == hi; }
  bool contains_zero() const noexcept { return nan || (lo <= 0.0 && hi >= 0.0); }
};

// Outward by a few units in the last place (and below the smallest normal, by that).
inline double down(double x) noexcept {
  if (x == -kInf || std::isnan(x)) return x;
  return x - (std::abs(x) * 1e-15 + 1e-300);
}
inline double up(double x) noexcept {
  if (x == kInf || std::isnan(x)) return x;
  return x + (std::abs(x) * 1e-15 + 1e-300);
}

// [lo, hi] rounded outwards; NaN ends (inf - inf) make the value undefined.
inline IV make(double lo, double hi, bool nan = false) noexcept {
  if (nan || std::isnan(lo) || std::isnan(hi)) return IV::undefined();
  return {down(lo), up(hi), false};
}

inline IV hull(const IV& a, const IV& b) noexcept {
  if (a.nan || b.nan) return IV::undefined();
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi), false};
}

inline IV operator+(const IV& a, const IV& b) noexcept { return make(a.lo + b.lo, a.hi + b.hi, a.nan || b.nan); }
inline IV operator-(const IV& a) noexcept { return {-a.hi, -a.lo, a.nan}; }
inline IV operator-(const IV& a, const IV& b) noexcept { return make(a.lo - b.hi, a.hi - b.lo, a.nan || b.nan); }

// Products of interval ends; 0 * inf counts as 0 (the end is a limit of finite values).
inline double times(double a, double b) noexcept { return a == 0.0 || b == 0.0 ? 0.0 : a * b; }
inline IV operator*(const IV& a, const IV& b) noexcept {
  if (a.nan || b.nan) return IV::undefined();
  const double p[4] = {times(a.lo, b.lo), times(a.lo, b.hi), times(a.hi, b.lo), times(a.hi, b.hi)};
  return make(std::min(std::min(p[0], p[1]), std::min(p[2], p[3])),
              std::max(std::max(p[0], p[1]), std::max(p[2], p[3])));
}

inline IV operator/(const IV& a, const IV& b) noexcept {
  if (a.nan || b.nan || b.contains_zero()) return IV::undefined();
  const double p[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  return make(std::min(std::min(p[0], p[1]), std::min(p[2], p[3])),
              std::max(std::max(p[0], p[1]), std::max(p[2], p[3])));
}

inline IV intersect(const IV& a, const IV& b) noexcept {
  if (a.nan) return b;
  if (b.nan) return a;
  return {std::max(a.lo, b.lo), std::min(a.hi, b.hi), false};
}

inline IV square(const IV& a) noexcept {
  if (a.nan) return a;
  if (a.lo >= 0.0) return make(a.lo * a.lo, a.hi * a.hi);
  if (a.hi <= 0.0) return make(a.hi * a.hi, a.lo * a.lo);
  return {0.0, up(std::max(a.lo * a.lo, a.hi * a.hi)), false};
}

}  // namespace trivox::detail
