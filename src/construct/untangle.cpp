// Untangling by L-BFGS on the interior control points (see untangle.h); the objective it
// minimises is in untangle_objective.cpp.
#include "trivox/construct/untangle.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "construct/untangle_objective.h"
#include "trivox/error.h"
#include "trivox/math.h"
#include "trivox/spline/refine.h"

namespace trivox {
namespace {

using detail::Objective;
using detail::ReferenceObjective;

TensorSpline refine_uniformly(TensorSpline s, int knots_per_span) {
  for (int d = 0; d < 3; ++d) {
    const std::vector<double> k(s.knots(d).knots().begin(), s.knots(d).knots().end());
    const double lo = s.lo(d), hi = s.hi(d);
    for (std::size_t i = 0; i + 1 < k.size(); ++i) {
      const double a = std::max(k[i], lo), b = std::min(k[i + 1], hi);
      if (!(b > a)) continue;
      for (int m = 1; m <= knots_per_span; ++m) s = insert_knot(s, d, a + (b - a) * m / (knots_per_span + 1));
    }
  }
  return s;
}

double dotv(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

void check_untangle_input(const TensorSpline& volume, const UntangleParams& params) {
  if (volume.param_dim() != 3 || volume.point_dim() != 3)
    throw ModelError("untangle: expected a trivariate with 3D points");
  if (volume.is_rational())
    throw ModelError("untangle: the volume is rational; only polynomial volumes can be untangled");
  for (int d = 0; d < 3; ++d)
    if (volume.knots(d).is_periodic())
      throw ModelError("untangle: the volume is periodic; only clamped volumes can be untangled");
  if (params.knots_per_span < 0 || params.knots_per_span > 8)
    throw ModelError(fmt::format("untangle: knots_per_span must be 0 to 8, got {}", params.knots_per_span));
  if (params.samples_per_span < 1 || params.iterations < 0 || !(params.target_relative > 0.0))
    throw ModelError("untangle: samples_per_span >= 1, iterations >= 0 and target_relative > 0 are required");
}

// 1 for the coordinates that may move (those of interior control points), 0 elsewhere.
std::vector<double> interior_mask(const TensorSpline& s) {
  const int nu = s.num_ctrl(0), nv = s.num_ctrl(1), nw = s.num_ctrl(2);
  std::vector<double> mask(static_cast<std::size_t>(3 * s.total_ctrl()), 0.0);
  for (int k = 1; k + 1 < nw; ++k)
    for (int j = 1; j + 1 < nv; ++j)
      for (int i = 1; i + 1 < nu; ++i)
        for (int c = 0; c < 3; ++c) mask[static_cast<std::size_t>(3 * s.ctrl_linear(i, j, k) + c)] = 1.0;
  return mask;
}

// The objective of one untangling, fast or reference, with its sign and scale (set from the
// dets of the starting points).
class Problem {
 public:
  Problem(const TensorSpline& s, const UntangleParams& params, bool reference) : target_(params.target_relative) {
    if (reference)
      slow_.emplace(s, params.samples_per_span);
    else
      fast_.emplace(s, params.samples_per_span, params.threads);
  }
  bool reference() const { return slow_.has_value(); }

  void dets(const std::vector<double>& p, std::vector<double>& out) const {
    if (slow_)
      out = slow_->dets(p);
    else
      fast_->dets(p, out);
  }
  // sigma: the sign of the sum of the dets; scale: the mean |det|.
  void set_scale(const std::vector<double>& det) {
    double sum = 0.0, abs_sum = 0.0;
    for (double d : det) {
      sum += d;
      abs_sum += std::abs(d);
    }
    sigma_ = sum < 0.0 ? -1.0 : 1.0;
    scale_ = abs_sum / static_cast<double>(det.size());
    if (!(scale_ > 0.0)) throw ModelError("untangle: det J vanishes at every sample (a flat volume)");
  }
  // F at p and its gradient, the fast objective from the dets of p that dets() gave.
  double value_gradient(const std::vector<double>& p, const std::vector<double>& det, std::vector<double>* grad) const {
    if (slow_) return slow_->value_gradient(p, sigma_, scale_, target_, grad);
    return fast_->value_gradient(p, det, sigma_, scale_, target_, grad);
  }
  // F at p and its gradient; `det` receives the dets of p (the fast objective only).
  double evaluate(const std::vector<double>& p, std::vector<double>& det, std::vector<double>* grad) const {
    if (slow_) return slow_->value_gradient(p, sigma_, scale_, target_, grad);
    fast_->dets(p, det);
    return fast_->value_gradient(p, det, sigma_, scale_, target_, grad);
  }
  // The samples below the target and the least sigma det / scale, at p whose dets are `det`
  // (the reference forms them again).
  void stats(const std::vector<double>& p, const std::vector<double>& det, int& below, double& min_rel) const {
    below = 0;
    min_rel = INFINITY;
    for (double d : slow_ ? slow_->dets(p) : det) {
      const double r = sigma_ * d / scale_;
      if (r < target_) ++below;
      min_rel = std::min(min_rel, r);
    }
  }

 private:
  std::optional<Objective> fast_;
  std::optional<ReferenceObjective> slow_;
  double target_, sigma_ = 1.0, scale_ = 1.0;
};

// L-BFGS's memory of the last 8 steps s and gradient changes y (Nocedal and Wright,
// Algorithm 7.4), and its two-loop recursion.
class LbfgsMemory {
 public:
  explicit LbfgsMemory(bool reference) : reference_(reference) {}

  bool empty() const { return ss_.empty(); }
  void clear() {
    ss_.clear();
    ys_.clear();
    ys_ss_.clear();
  }
  // dir = -H g on the masked coordinates; before any pair, H is gamma I with a step of
  // 1e-3 diag along g.
  void direction(const std::vector<double>& g, const std::vector<double>& mask, double diag,
                 std::vector<double>& dir) const {
    dir = g;
    std::vector<double> alpha(ss_.size());
    for (std::size_t m = ss_.size(); m-- > 0;) {
      alpha[m] = dotv(ss_[m], dir) / y_dot_s(m);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] -= alpha[m] * ys_[m][i];
    }
    double gamma;
    if (ss_.empty()) {
      const double gn = std::sqrt(dotv(g, g));
      gamma = gn > 0.0 ? 1e-3 * diag / gn : 1.0;
    } else {
      gamma = reference_ ? dotv(ss_.back(), ys_.back()) / dotv(ys_.back(), ys_.back()) : newest_sy_ / newest_yy_;
    }
    for (double& d : dir) d *= gamma;
    for (std::size_t m = 0; m < ss_.size(); ++m) {
      const double beta = dotv(ys_[m], dir) / y_dot_s(m);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] += ss_[m][i] * (alpha[m] - beta);
    }
    for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -dir[i] * mask[i];
  }
  // Keeps the pair (sv, yv) of a step whose s . y is `sy`, when that is positive.
  void add(std::vector<double>&& sv, std::vector<double>&& yv, double sy) {
    if (!(sy > 1e-300)) return;
    if (!reference_) {
      ys_ss_.push_back(dotv(yv, sv));
      newest_sy_ = sy;
      newest_yy_ = dotv(yv, yv);
    }
    ss_.push_back(std::move(sv));
    ys_.push_back(std::move(yv));
    if (ss_.size() > 8) {
      ss_.pop_front();
      ys_.pop_front();
      if (!reference_) ys_ss_.pop_front();
    }
  }

 private:
  double y_dot_s(std::size_t m) const { return reference_ ? dotv(ys_[m], ss_[m]) : ys_ss_[m]; }

  bool reference_;
  std::deque<std::vector<double>> ss_, ys_;
  // y_m . s_m and, for the newest pair, s . y and y . y: the same every time the recursion
  // asks, so the fast path forms them once per pair (the reference forms them each time).
  std::deque<double> ys_ss_;
  double newest_sy_ = 0.0, newest_yy_ = 0.0;
};

// The descent from x: L-BFGS with a backtracking (Armijo) line search on the masked
// coordinates, at most params.iterations steps. x, its dets and F end at the last accepted
// point; returns the steps taken.
struct Descent {
  const Problem& problem;
  const std::vector<double>& mask;
  double diag;  // the control box's diagonal: the scale of a first step
  std::vector<double> x, det_x;
  double f = 0.0;
  int evaluations = 1;  // the dets at x, from which F and its gradient at x come

  int run(const UntangleParams& params) {
    std::vector<double> g(x.size()), gnew(x.size()), dir(x.size()), xnew(x.size()), det_new;
    f = problem.value_gradient(x, det_x, &g);
    for (std::size_t i = 0; i < g.size(); ++i) g[i] *= mask[i];
    LbfgsMemory memory(problem.reference());
    int it = 0;
    for (; it < params.iterations && f > 0.0; ++it) {
      if (params.stop != nullptr && params.stop->load()) throw CancelledError("stopped while untangling a volume");
      memory.direction(g, mask, diag, dir);
      double slope = dotv(g, dir);
      if (!(slope < 0.0)) {  // not a descent direction: restart from steepest descent
        memory.clear();
        const double gn = std::sqrt(dotv(g, g));
        // A zero gradient (the samples still below the target are where no interior point can
        // move det J, such as a face that collapses to a line): x is where the descent ends.
        // The steepest descent from it would be 0 / 0 in every coordinate, and every step of
        // the line search NaN, so that it fails and ends the loop with x as it is; this ends
        // it at once.
        if (!problem.reference() && !(gn > 0.0)) break;
        for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -g[i] * 1e-3 * diag / gn;
        slope = dotv(g, dir);
      }
      double fnew = f;
      if (!line_search(dir, slope, xnew, det_new, gnew, fnew)) break;
      for (std::size_t i = 0; i < gnew.size(); ++i) gnew[i] *= mask[i];
      std::vector<double> sv(x.size()), yv(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) {
        sv[i] = xnew[i] - x[i];
        yv[i] = gnew[i] - g[i];
      }
      const double sy = dotv(sv, yv);
      memory.add(std::move(sv), std::move(yv), sy);
      x.swap(xnew);
      g.swap(gnew);
      det_x.swap(det_new);
      f = fnew;
    }
    return it;
  }

  // Halves the step from 1 until F falls by the Armijo fraction (at most 40 tries): the point
  // into xnew, its dets, gradient and F; false when no step is accepted.
  bool line_search(const std::vector<double>& dir, double slope, std::vector<double>& xnew,
                   std::vector<double>& det_new, std::vector<double>& gnew, double& fnew) {
    double step = 1.0;
    for (int tries = 0; tries < 40; ++tries, step *= 0.5) {
      for (std::size_t i = 0; i < x.size(); ++i) xnew[i] = x[i] + step * dir[i];
      ++evaluations;
      fnew = problem.evaluate(xnew, det_new, &gnew);
      if (fnew <= f + 1e-4 * step * slope) return true;
    }
    return false;
  }
};

// The untangling, with the fast objective, or with the reference objective and without the
// stop at a zero gradient (detail::untangle_reference): the two give the same volume, bit for
// bit, which the tests check.
UntangleResult untangle_with(const TensorSpline& volume, const UntangleParams& params, bool reference) {
  check_untangle_input(volume, params);
  TensorSpline s = refine_uniformly(volume, params.knots_per_span);
  const int nu = s.num_ctrl(0), nv = s.num_ctrl(1), nw = s.num_ctrl(2);
  if (nu < 3 || nv < 3 || nw < 3)
    throw ModelError(fmt::format("untangle: the volume has no interior control points ({} x {} x {})", nu, nv, nw));

  const std::vector<double> mask = interior_mask(s);
  Problem problem(s, params, reference);
  Descent descent{problem, mask, 0.0, std::vector<double>(s.points().begin(), s.points().end()), {}};
  // The dets at x, kept with x (the fast objective's F, its gradient and the statistics come
  // from them).
  problem.dets(descent.x, descent.det_x);
  problem.set_scale(descent.det_x);
  UntangleResult result{s, 0, 0, 0, 0, 0, 0};
  problem.stats(descent.x, descent.det_x, result.below_target_before, result.min_relative_before);
  descent.diag = s.control_box().diagonal();
  result.iterations = descent.run(params);
  result.evaluations = descent.evaluations;
  result.spline = TensorSpline(s.all_knots(), 3, descent.x);
  problem.stats(descent.x, descent.det_x, result.below_target_after, result.min_relative_after);
  return result;
}

}  // namespace

namespace detail {

double untangle_objective(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                          double target_relative, std::vector<double>* gradient) {
  const Objective obj(s, samples_per_span, 0);
  const std::vector<double> x(s.points().begin(), s.points().end());
  if (gradient) gradient->assign(x.size(), 0.0);
  std::vector<double> det;
  obj.dets(x, det);
  return obj.value_gradient(x, det, sigma, scale, target_relative, gradient);
}

double untangle_objective_reference(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                                    double target_relative, std::vector<double>* gradient) {
  const ReferenceObjective obj(s, samples_per_span);
  const std::vector<double> x(s.points().begin(), s.points().end());
  if (gradient) gradient->assign(x.size(), 0.0);
  return obj.value_gradient(x, sigma, scale, target_relative, gradient);
}

UntangleResult untangle_reference(const TensorSpline& volume, const UntangleParams& params) {
  return untangle_with(volume, params, true);
}

}  // namespace detail

UntangleResult untangle(const TensorSpline& volume, const UntangleParams& params) {
  return untangle_with(volume, params, false);
}

}  // namespace trivox
