// Helpers for the material kinds' enclosures (MaterialFunction::enclose).
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/fraction_enclosure.h"

namespace trivox::detail {

// The rounding of a value to float (and a few float operations on it): relative 2^-21.
inline double float_slack(double x) noexcept { return std::abs(x) * 0x1p-21 + 1e-38; }

// `e` as the float values a part passes on: every interval widened by their rounding, and the
// sum by the rounding of every term.
inline FractionEnclosure as_floats(FractionEnclosure e) {
  double terms = 0.0;
  for (Interval& f : e.fractions) {
    const double slack = std::max(float_slack(f.lo), float_slack(f.hi));
    f.lo -= slack;
    f.hi += slack;
    terms += slack;
  }
  e.sum.lo -= terms;
  e.sum.hi += terms;
  return e;
}

// The value of a scalar source (a one-output function's enclosure), NaN meaning unknown.
inline Interval scalar_of(const FractionEnclosure& e) { return e.fractions.front(); }

// [lo, hi] clamped to [0, 1].
inline Interval unit_clamped(Interval t) noexcept { return {std::clamp(t.lo, 0.0, 1.0), std::clamp(t.hi, 0.0, 1.0)}; }

// The ramp of gradient stops (scalar_gradient_material.h) over values s in `s`: the
// fractions and their sum are piecewise linear in s between stops and constant beyond the
// ends, so their extremes lie at the ends of `s` or at stops inside it.
inline FractionEnclosure ramp_enclosure(std::span<const GradientStop> stops, Interval s, bool finite) {
  const std::size_t m = stops.front().fractions.size();
  FractionEnclosure e;
  e.finite = finite && std::isfinite(s.lo) && std::isfinite(s.hi);
  if (!e.finite) {
    // Infinite values still ramp to the end stops; NaN does not.
    e = FractionEnclosure::unknown(static_cast<int>(m));
    return e;
  }
  std::vector<float> at(m);
  bool first = true;
  const auto include = [&](std::span<const float> f) {
    double sum = 0.0;
    for (float v : f) sum += v;
    if (first) {
      e.fractions.assign(m, Interval{});
      for (std::size_t j = 0; j < m; ++j) e.fractions[j] = Interval::point(f[j]);
      e.sum = Interval::point(sum);
      first = false;
      return;
    }
    for (std::size_t j = 0; j < m; ++j) e.fractions[j] = e.fractions[j].hull(Interval::point(f[j]));
    e.sum = e.sum.hull(Interval::point(sum));
  };
  gradient_ramp(stops, s.lo, at);
  include(at);
  gradient_ramp(stops, s.hi, at);
  include(at);
  for (const GradientStop& stop : stops)
    if (stop.value >= s.lo && stop.value <= s.hi) include(stop.fractions);
  // Between breakpoints the ramp interpolates in double and rounds to float.
  return as_floats(e);
}

}  // namespace trivox::detail
