// Enclosures of what a material function gives over a region of its cell: an interval for
// each fraction and one for their sum, as evaluate_row computes them (its float results
// included), so that a scene's fraction rules can be proved before slicing
// (fraction_check.h) rather than met half-way through a job.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

namespace trivox {

// A closed interval [lo, hi] of reals; an end may be infinite.
struct Interval {
  double lo = 0.0, hi = 0.0;

  static Interval everything() noexcept {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  static Interval point(double x) noexcept { return {x, x}; }
  bool contains(double x) const noexcept { return lo <= x && x <= hi; }
  bool bounded() const noexcept {
    return lo > -std::numeric_limits<double>::infinity() && hi < std::numeric_limits<double>::infinity();
  }
  Interval hull(const Interval& o) const noexcept { return {std::min(lo, o.lo), std::max(hi, o.hi)}; }
};

struct FractionEnclosure {
  // One per material: every fraction the function gives in the region lies in its interval.
  std::vector<Interval> fractions;
  // Their sum: often much tighter than the sum of the intervals (1 - u and u sum to exactly 1).
  Interval sum;
  // False when a value may not be a finite number (a division by an interval holding 0, the
  // square root of an interval reaching below 0): then nothing is proved.
  bool finite = true;

  // m materials, nothing known: every interval everything, not finite.
  static FractionEnclosure unknown(int num_materials);

  // For a kind that gives each point one whole material or void (porous tiles, twisting
  // curves): the sum is 0 or one of the fractions, so it lies in [0, the largest upper end].
  void sum_of_one_material() noexcept {
    sum = {0.0, 0.0};
    for (const Interval& f : fractions) sum.hi = std::max(sum.hi, f.hi);
  }
};

}  // namespace trivox
