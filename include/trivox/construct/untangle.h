// Untangling a folded volume: its boundary control points (and so its six faces) stay
// exactly where they are, and only the interior control points move, to make det J take one
// sign everywhere. A Coons volume interpolates its faces but its interior, and the
// cross-boundary derivative on its faces, come from a blend that folds for shapes far from
// convex (the duck); moving the interior points changes neither the faces nor the knots.
//
// The interior points x minimise F(x) = sum over samples s of max(0, target - sigma det J_s /
// scale)^2 on a grid of parameter samples (faces included), where sigma is the sign of the
// volume (the majority sign of det J before untangling) and scale the mean |det J| of the
// input, so `target` is the aimed-for minimum of det J relative to its mean. det J is a cubic
// polynomial in the control points; its gradient with respect to point P_c is
//   dN_c/du (J_v x J_w) + dN_c/dv (J_w x J_u) + dN_c/dw (J_u x J_v),
// and F is minimised by L-BFGS with a backtracking line search. F = 0 means every sample
// meets the target; the result is still only checked at samples (as every Jacobian check is).
#pragma once

#include <atomic>

#include <vector>

#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct UntangleParams {
  // Knots inserted uniformly into every span of every direction first (exact refinement),
  // which gives the interior more freedom near the faces. 0 to 8.
  int knots_per_span = 1;
  int iterations = 400;  // L-BFGS iterations at most; stops earlier when F = 0
  // Samples per knot span of the refined volume per direction (both ends of the domain
  // included); the grid should be finer than any check grid used afterwards.
  int samples_per_span = 3;
  double target_relative = 0.05;  // aimed-for minimum of sigma det J / mean |det J|
  // Threads that sample det J (0: every core). The result is the same for any count.
  int threads = 0;
  // Checked every iteration: once true, untangle() throws CancelledError.
  const std::atomic<bool>* stop = nullptr;
};

struct UntangleResult {
  TensorSpline spline;  // the refined volume with moved interior points
  int iterations = 0;
  // Evaluations of F (each a pass over every sample): the work, for the tests and benchmarks.
  int evaluations = 0;
  // On the objective's sample grid, before and after: samples below the target, and the
  // smallest sigma det J / scale.
  int below_target_before = 0, below_target_after = 0;
  double min_relative_before = 0.0, min_relative_after = 0.0;
};

// Throws ModelError for a rational or periodic volume (the weights would have to move with
// the points) and for a volume without interior control points.
UntangleResult untangle(const TensorSpline& volume, const UntangleParams& params = {});

namespace detail {
// The objective F of the points of polynomial volume `s` on its grid of `samples_per_span`
// samples per knot span (both domain ends included), and when `gradient` is given its
// gradient with respect to every coordinate of every control point (3 per point, in the
// spline's order). Exposed for the tests.
double untangle_objective(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                          double target_relative, std::vector<double>* gradient);
// The same, one sample at a time in the grid's order: the slow, obvious reference the fast
// objective (det J of four samples at once, on several threads) must match bit for bit.
double untangle_objective_reference(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                                    double target_relative, std::vector<double>* gradient);
// untangle() driven by the reference objective, and without its early stop at a zero gradient
// (where the line search can only fail): the volume untangle() must match bit for bit.
UntangleResult untangle_reference(const TensorSpline& volume, const UntangleParams& params = {});
}  // namespace detail

}  // namespace trivox
