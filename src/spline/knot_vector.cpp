#include "trivox/spline/knot_vector.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

KnotVector::KnotVector(int order, std::vector<double> knots) : order_(order), knots_(std::move(knots)) {
  validate();
  prepare_span_guess();
}

void KnotVector::prepare_span_guess() noexcept {
  const std::size_t n = knots_.size();
  inverse_differences_.assign(static_cast<std::size_t>(std::max(order_ - 1, 0)) * n, 0.0);
  for (int len = 1; len < order_; ++len)
    for (std::size_t a = 0; a + static_cast<std::size_t>(len) < n; ++a) {
      const double d = knots_[a + static_cast<std::size_t>(len)] - knots_[a];
      inverse_differences_[static_cast<std::size_t>(len - 1) * n + a] = d > 0 ? 1.0 / d : 0.0;
    }
  const double a = lo(), b = hi();
  const int pieces = num_basis() - order_ + 1;  // spans between t_{k-1} and t_{nb}
  const double width = (b - a) / pieces;
  for (int s = order_ - 1; s < num_basis(); ++s) {
    const double w = knots_[static_cast<std::size_t>(s + 1)] - knots_[static_cast<std::size_t>(s)];
    if (std::abs(w - width) > 1e-12 * (b - a)) return;  // repeated or uneven knots
  }
  uniform_inverse_width_ = 1.0 / width;
}

KnotVector KnotVector::periodic(int order, int num_ctrl, std::vector<double> knots) {
  if (num_ctrl < 1)
    throw ModelError(fmt::format("periodic knot vector needs at least one control point, got {}", num_ctrl));
  const auto expected = static_cast<std::size_t>(num_ctrl) + 2 * static_cast<std::size_t>(std::max(order, 0)) - 1;
  if (knots.size() != expected)
    throw ModelError(
        fmt::format("periodic knot vector of order {} with {} control points needs {} knots (n + 2*order - 1), got {}",
                    order, num_ctrl, expected, knots.size()));
  KnotVector kv;
  kv.order_ = order;
  kv.periodic_ = true;
  kv.knots_ = std::move(knots);
  kv.validate();
  kv.prepare_span_guess();
  return kv;
}

KnotVector KnotVector::clamped_uniform(int order, int num_ctrl, double lo, double hi) {
  if (order < 1 || num_ctrl < order)
    throw ModelError(
        fmt::format("uniform knot vector needs order >= 1 and at least order control points (order {}, {} points)",
                    order, num_ctrl));
  std::vector<double> knots;
  knots.reserve(static_cast<std::size_t>(num_ctrl + order));
  const int pieces = num_ctrl - order + 1;
  for (int i = 0; i < order; ++i) knots.push_back(lo);
  for (int i = 1; i < pieces; ++i) knots.push_back(lo + (hi - lo) * i / pieces);
  for (int i = 0; i < order; ++i) knots.push_back(hi);
  return KnotVector(order, std::move(knots));
}

void KnotVector::validate() const {
  if (order_ < 1 || order_ > kMaxOrder)
    throw ModelError(fmt::format("order {} is outside the supported range 1..{}", order_, kMaxOrder));
  if (knots_.size() < 2 * static_cast<std::size_t>(order_))
    throw ModelError(
        fmt::format("a knot vector of order {} needs at least {} knots, got {}", order_, 2 * order_, knots_.size()));
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    if (!std::isfinite(knots_[i])) throw ModelError(fmt::format("knot {} is not a finite number", i));
    if (i > 0 && knots_[i] < knots_[i - 1])
      throw ModelError(fmt::format("knots decrease at index {} ({} after {})", i, knots_[i], knots_[i - 1]));
  }
  // A multiplicity above the order makes a basis function identically zero (a gap in the
  // basis); end knots of a clamped vector reach exactly the order.
  std::size_t run = 1;
  for (std::size_t i = 1; i <= knots_.size(); ++i) {
    if (i < knots_.size() && knots_[i] == knots_[i - 1]) {
      ++run;
      continue;
    }
    if (run > static_cast<std::size_t>(order_))
      throw ModelError(fmt::format("knot {} has multiplicity {}, above the order {}", knots_[i - 1], run, order_));
    run = 1;
  }
  if (!(hi() > lo())) throw ModelError(fmt::format("empty parametric domain [{}, {}]", lo(), hi()));
}

bool KnotVector::is_clamped() const noexcept {
  const auto k = static_cast<std::size_t>(order_);
  const std::size_t n = knots_.size();
  return !periodic_ && knots_[0] == knots_[k - 1] && knots_[n - k] == knots_[n - 1];
}

int KnotVector::find_span(double t) const noexcept {
  const int nb = num_basis();
  const double a = lo(), b = hi();
  if (!(t > a)) {
    // At or below the lower end: the first non-empty span at or after k-1.
    int s = order_ - 1;
    while (s < nb - 1 && knots_[static_cast<std::size_t>(s + 1)] <= a) ++s;
    return s;
  }
  if (t >= b) {
    // At or above the upper end: the last non-empty span, so that V(hi) is the limit from
    // the left (exact at the domain end, also with repeated interior knots before it).
    int s = nb - 1;
    while (s > order_ - 1 && knots_[static_cast<std::size_t>(s)] >= b) --s;
    return s;
  }
  if (uniform_inverse_width_ > 0.0) {
    // Guess from the uniform width, then step to the exact span (rounding can put the guess
    // one off at a knot).
    int s = order_ - 1 + static_cast<int>((t - a) * uniform_inverse_width_);
    s = std::clamp(s, order_ - 1, nb - 1);
    while (s > order_ - 1 && t < knots_[static_cast<std::size_t>(s)]) --s;
    while (s < nb - 1 && t >= knots_[static_cast<std::size_t>(s + 1)]) ++s;
    return s;
  }
  // upper_bound gives the first knot > t; the span starts one before it.
  const auto first = knots_.begin() + (order_ - 1);
  const auto last = knots_.begin() + (nb + 1);
  const auto it = std::upper_bound(first, last, t);
  return static_cast<int>(it - knots_.begin()) - 1;
}

int KnotVector::multiplicity(double t) const noexcept {
  return static_cast<int>(std::count(knots_.begin(), knots_.end(), t));
}

std::vector<double> KnotVector::interior_breaks() const {
  std::vector<double> out;
  const double a = lo(), b = hi();
  for (double t : knots_)
    if (t > a && t < b && (out.empty() || out.back() != t)) out.push_back(t);
  return out;
}

}  // namespace trivox
