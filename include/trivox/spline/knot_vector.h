// Knot vectors of B-spline bases: clamped (open), unclamped and periodic.
//
// Conventions (The NURBS Book, Section 2.2): a basis of `num_basis` functions of order
// k = degree + 1 has num_basis + k knots t_0 <= ... <= t_{num_basis+k-1}; its parametric
// domain is [t_{k-1}, t_{num_basis}]. A periodic knot vector (IRIT's `[KVP`) with n distinct
// control points evaluates as an unclamped basis of n + k - 1 functions whose control index
// i >= n wraps to i mod n; it stores n + 2k - 1 knots.
#pragma once

#include <span>
#include <vector>

namespace trivox {

// Orders above this are rejected: the evaluators keep per-direction basis values in
// fixed-size stack arrays so that the hot path never allocates.
inline constexpr int kMaxOrder = 32;

class KnotVector {
 public:
  // An ordinary (clamped or unclamped) knot vector. Throws ModelError when the order is
  // outside [1, kMaxOrder], the knots decrease, are not finite, a knot's multiplicity
  // exceeds the order, there are fewer than 2*order knots, or the domain is empty.
  KnotVector(int order, std::vector<double> knots);

  // IRIT's periodic knot vector for `num_ctrl` distinct control points: `knots` must hold
  // num_ctrl + 2*order - 1 values. Throws ModelError like the constructor.
  static KnotVector periodic(int order, int num_ctrl, std::vector<double> knots);

  // Clamped uniform knots on [lo, hi] for `num_ctrl` control points (G+Smo's mode="uniform").
  static KnotVector clamped_uniform(int order, int num_ctrl, double lo = 0.0, double hi = 1.0);

  // The Bezier basis of the given order on [0, 1].
  static KnotVector bezier(int order) { return clamped_uniform(order, order); }

  int order() const noexcept { return order_; }
  int degree() const noexcept { return order_ - 1; }
  // Number of basis functions (for a periodic vector, including the wrapped ones).
  int num_basis() const noexcept { return static_cast<int>(knots_.size()) - order_; }
  // Number of distinct control points this basis addresses.
  int num_ctrl() const noexcept { return periodic_ ? num_basis() - order_ + 1 : num_basis(); }
  bool is_periodic() const noexcept { return periodic_; }
  // Control point addressed by basis function i (i mod num_ctrl for a periodic vector).
  int ctrl_index(int basis_index) const noexcept {
    return periodic_ && basis_index >= num_ctrl() ? basis_index - num_ctrl() : basis_index;
  }
  std::span<const double> knots() const noexcept { return knots_; }
  // 1 / (t_{a+len} - t_a), or 0 where the knots coincide, for len = 1..order-1: the
  // denominators of the basis recurrences, so that evaluation multiplies instead of divides.
  // Row `len` starts at index (len - 1) * knots().size().
  const double* inverse_differences(int len) const noexcept {
    return inverse_differences_.data() + static_cast<std::size_t>(len - 1) * knots_.size();
  }
  double operator[](int i) const noexcept { return knots_[static_cast<std::size_t>(i)]; }
  double lo() const noexcept { return knots_[static_cast<std::size_t>(order_ - 1)]; }
  double hi() const noexcept { return knots_[static_cast<std::size_t>(num_basis())]; }
  // True when the first and last `order` knots are equal (the curve interpolates its ends).
  bool is_clamped() const noexcept;

  // Index s of the knot span [t_s, t_{s+1}) holding t, with k-1 <= s <= num_basis-1 and
  // t_s < t_{s+1}. Values outside the domain are clamped to it; t == hi() gives the last
  // non-empty span, so evaluation at the upper end is exact. Binary search; no allocation.
  int find_span(double t) const noexcept;

  // How many knots equal t exactly.
  int multiplicity(double t) const noexcept;

  // The distinct knot values inside the open domain (lo, hi): the breakpoints between
  // polynomial pieces.
  std::vector<double> interior_breaks() const;

  bool operator==(const KnotVector&) const = default;

 private:
  KnotVector() = default;
  void validate() const;
  void prepare_span_guess() noexcept;

  // 1 / (span width) when the non-empty spans inside the domain are all equally wide (the
  // common uniform case): find_span then guesses the span in O(1) and corrects it exactly.
  // 0 otherwise (binary search).
  double uniform_inverse_width_ = 0.0;
  std::vector<double> inverse_differences_;
  int order_ = 1;
  bool periodic_ = false;
  std::vector<double> knots_;
};

}  // namespace trivox
