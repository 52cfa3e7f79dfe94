#include "trivox/material/fraction_check.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <queue>
#include <utility>

#include <fmt/format.h>

#include "material/enclosure_util.h"
#include "material/spline_coefficient_bounds.h"

namespace trivox {

namespace {

std::string name_of(const std::vector<std::string>& names, std::size_t j) {
  return j < names.size() ? fmt::format("'{}'", names[j]) : fmt::format("{}", j);
}

// Positions of the cell at parameters in `box`: the control hull of the geometry restricted
// to the box (tight, it shrinks with the box); for a large geometry the hull of the control
// points whose basis functions reach the box (cheaper; down to a knot span).
Box3 positions(const TensorSpline& geometry, const ParamBox& box) {
  if (geometry.total_ctrl() <= 1000) return detail::restricted_piece(geometry, box).control_box();
  std::array<double, 3> lo{}, hi{};
  detail::coefficient_bounds(geometry, box, lo, hi);
  return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
}

// The rule the policy applies to one sample, as apply_fraction_policy applies it; empty when
// the sample passes.
std::string broken_rule(std::span<const float> f, const FractionPolicy& policy, const std::vector<std::string>& names) {
  const bool strict = policy.policy == SumPolicy::kError;
  double sum = 0.0;
  for (std::size_t j = 0; j < f.size(); ++j) {
    if (!std::isfinite(f[j]))
      return fmt::format("the fraction of material {} is {}, not a finite number", name_of(names, j), f[j]);
    if (f[j] < 0.0f) {
      if (strict && f[j] < -policy.tolerance)
        return fmt::format("the fraction of material {} is {:.6g} < 0 (tolerance {})", name_of(names, j), f[j],
                           policy.tolerance);
    } else {
      sum += f[j];
    }
  }
  if (strict && sum > 1.0 + policy.tolerance)
    return fmt::format("the fractions sum to {:.6g} > 1 (tolerance {})", sum, policy.tolerance);
  return {};
}

// A box with what its enclosure allows there.
struct Assessed {
  ParamBox box;
  double sum_bound = 0.0;       // the policy's sum (fractions below 0 count as 0)
  double fraction_bound = 0.0;  // the smallest fraction
  bool finite = true;
  double badness = 0.0;  // how far beyond the rule the bounds reach (<= 0: proved); infinite when not finite
  bool operator<(const Assessed& o) const noexcept { return badness < o.badness; }
};

}  // namespace

FractionCheck check_fractions(const MaterialFunction& material, const FractionPolicy& policy,
                              const TensorSpline& geometry, const std::vector<std::string>& names,
                              const FractionCheckParams& params) {
  const bool strict = policy.policy == SumPolicy::kError;
  const auto m = static_cast<std::size_t>(material.num_materials());
  const ParamBox domain{{geometry.lo(0), geometry.lo(1), geometry.lo(2)},
                        {geometry.hi(0), geometry.hi(1), geometry.hi(2)}};
  FractionCheck result;
  result.sum_bound = -std::numeric_limits<double>::infinity();
  result.fraction_bound = std::numeric_limits<double>::infinity();
  const auto assess = [&](const ParamBox& box) {
    ++result.boxes;
    const FractionEnclosure e = detail::as_floats(material.enclose(box, positions(geometry, box)));
    Assessed a;
    a.box = box;
    // The policy's sum counts a fraction below 0 (within the tolerance) as 0: it can exceed
    // the sum of the fractions by their negative parts.
    a.sum_bound = e.sum.hi;
    a.fraction_bound = std::numeric_limits<double>::infinity();
    for (const Interval& f : e.fractions) {
      a.sum_bound += std::max(0.0, -f.lo);
      a.fraction_bound = std::min(a.fraction_bound, f.lo);
    }
    a.sum_bound += std::abs(a.sum_bound) * 1e-15 * static_cast<double>(m);  // its summation in double
    a.finite = e.finite && std::isfinite(a.sum_bound) && std::isfinite(a.fraction_bound);
    a.badness = !a.finite ? std::numeric_limits<double>::infinity()
                : strict  ? std::max(a.sum_bound - (1.0 + policy.tolerance), -policy.tolerance - a.fraction_bound)
                          : -1.0;
    return a;
  };
  std::priority_queue<Assessed> queue;
  queue.push(assess(domain));
  std::vector<float> sample(m);
  bool unproved = false;
  while (!queue.empty()) {
    const Assessed here = queue.top();
    queue.pop();
    const ParamBox& box = here.box;
    if (here.badness <= 0.0) {
      result.sum_bound = std::max(result.sum_bound, here.sum_bound);
      result.fraction_bound = std::min(result.fraction_bound, here.fraction_bound);
      continue;
    }
    // Inconclusive: does the material break the rule at the box's centre?
    const Vec3 centre = box.center();
    const std::array<double, 3> t{centre.x, centre.y, centre.z};
    std::array<double, 3> p{};
    geometry.evaluate(t, p);
    const Vec3 xyz{p[0], p[1], p[2]};
    material.evaluate(centre, xyz, sample);
    if (std::string rule = broken_rule(sample, policy, names); !rule.empty()) {
      result.outcome = FractionCheckOutcome::kBroken;
      result.uvw = centre;
      result.xyz = xyz;
      result.rule = std::move(rule);
      return result;
    }
    // Split in two along the direction whose halves the bounds judge best (the smallest sum
    // of their excesses: a thin band of bad values is cut off along its thin direction; on a
    // tie the widest, relative to the domain), among those still wider than the smallest
    // box; unless the budget is spent.
    const bool budget_left = result.boxes + 6 <= params.max_boxes;
    double best_score = std::numeric_limits<double>::infinity(), best_share = 0.0;
    std::optional<std::pair<Assessed, Assessed>> best;
    for (int d = 0; d < 3 && budget_left; ++d) {
      const double share = (box.hi[d] - box.lo[d]) / (domain.hi[d] - domain.lo[d]);
      if (share < params.min_box_relative) continue;
      ParamBox lo = box, hi = box;
      const double mid = 0.5 * (box.lo[d] + box.hi[d]);
      lo.hi[d] = mid;
      hi.lo[d] = mid;
      Assessed a = assess(lo), b = assess(hi);
      const double score = std::min(std::max(a.badness, 0.0) + std::max(b.badness, 0.0), 1e300);
      // Equal judgements (no half better than the other directions'): the widest direction.
      const bool better = !best || score < best_score * (1.0 - 1e-9) || (score <= best_score && share > best_share);
      if (better) {
        best_score = score;
        best_share = share;
        best.emplace(std::move(a), std::move(b));
      }
    }
    if (!best) {
      if (!unproved) {
        unproved = true;
        result.box = box;
        result.reason = !here.finite ? std::string("a value may not be a finite number")
                        : here.sum_bound > 1.0 + policy.tolerance
                            ? fmt::format("the sum may reach {:.6g}", here.sum_bound)
                            : fmt::format("a fraction may fall to {:.6g}", here.fraction_bound);
      }
      continue;
    }
    queue.push(std::move(best->first));
    queue.push(std::move(best->second));
  }
  if (unproved) result.outcome = FractionCheckOutcome::kUnproved;
  return result;
}

}  // namespace trivox
