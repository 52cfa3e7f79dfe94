// The objective of the untangling (untangle.cpp): F = sum over samples of max(0, target -
// sigma det J / scale)^2 and its gradient with respect to the control points, in two forms
// that give the same bits: the reference, one sample at a time, and the fast one, whose dets
// are formed four u samples at a time by a kernel compiled per SIMD target
// (untangle_kernels.cpp; docs/ARCHITECTURE.md, "SIMD targets").
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::detail {

// Basis values and derivatives of one direction at one sample: the `order` functions
// starting at control index `first`.
struct DirSample {
  int first = 0;
  std::vector<double> value, deriv;
};

// Uniform samples within each distinct knot span of `kv`, both domain ends included.
std::vector<DirSample> sample_direction(const KnotVector& kv, int samples_per_span);

// The Jacobian's columns (ju, jv, jw) at one sample of the volume whose control points are p
// (x, y, z per point, u fastest over nu x nv x ...), and their cross products, from which
// det J = ju . cvw and its gradient follow.
struct SampleJacobian {
  Vec3 ju, jv, jw;
  Vec3 cvw, cwu, cuv;  // jv x jw, jw x ju, ju x jv
};
SampleJacobian sample_jacobian(const double* p, int nu, int nv, const DirSample& su, const DirSample& sv,
                               const DirSample& sw);

// Adds coeff * d det J / d P at the sample (su, sv, sw) to g (3 per point, all points): the
// chain rule through the cross products of `j`.
void add_det_gradient(const SampleJacobian& j, int nu, int nv, const DirSample& su, const DirSample& sv,
                      const DirSample& sw, double coeff, std::vector<double>& g);

// The straightforward objective, one sample at a time in (w, v, u) order: the reference the
// fast objective is tested against (untangle_objective_reference), bit for bit.
class ReferenceObjective {
 public:
  ReferenceObjective(const TensorSpline& s, int samples_per_span);

  std::size_t num_samples() const { return samples_[0].size() * samples_[1].size() * samples_[2].size(); }

  // det J at every sample for control points `p` (3 per point, all points).
  std::vector<double> dets(const std::vector<double>& p) const;

  // F and its gradient (with respect to all points; the caller masks the boundary).
  double value_gradient(const std::vector<double>& p, double sigma, double scale, double target,
                        std::vector<double>* grad) const;

 private:
  std::array<std::vector<DirSample>, 3> samples_;
  std::array<int, 3> n_{};
};

// The lanes of the fast objective's kernel: four u samples at a time.
inline constexpr int kUntangleLanes = 4;

// What the dets kernel reads: the samples, the u samples in groups of at most
// kUntangleLanes sharing their first control point (one knot span), and the span cells whose
// points moved since the previous call.
struct UntangleTables {
  // Up to kUntangleLanes consecutive u samples with the same first control point.
  struct Group {
    std::size_t start = 0;
    int count = 0, first = 0;
    // Per basis function a: the samples' values (derivatives) at [a * kUntangleLanes + lane],
    // 0 in the lanes past `count`.
    std::vector<double> value, deriv;
  };
  std::array<std::vector<DirSample>, 3> samples;
  std::array<int, 3> n{};                // control points per direction
  std::array<int, 3> orders{}, cells{};  // per direction: the order, and n - order + 1 first points
  std::vector<Group> groups;
  std::vector<std::uint8_t> moved;  // per span cell (fu + cells[0] (fv + cells[1] fw)): 1 if it moved

  std::size_t cell(int fu, int fv, int fw) const {
    return static_cast<std::size_t>(fu + cells[0] * (fv + cells[1] * fw));
  }
};

// The dets of the samples with v sample `iv`, every u and w sample whose span cell moved, into
// out[iu + nu_s (iv + nv_s iw)]: each lane the reference's scalar operations for one sample,
// in the same order, so the same bits on every SIMD target (nothing is fused).
void untangle_dets_at_v(const UntangleTables& t, const double* p, std::size_t iv, double* out);

// The fast objective: the same sums as ReferenceObjective, computed in two passes.
//  1. det J at every sample, in parallel over the v samples, up to kUntangleLanes u samples
//     of one knot span at a time (they share their control points: each point is loaded once
//     for them all).
//  2. F and its gradient from those dets, sequentially in the reference's sample order (the
//     order of every rounding in the sums), recomputing J only at the samples below the
//     target (few: the gradient is zero elsewhere).
class Objective {
 public:
  Objective(const TensorSpline& s, int samples_per_span, int threads);

  std::size_t num_samples() const { return t_.samples[0].size() * t_.samples[1].size() * t_.samples[2].size(); }

  // det J at every sample for control points `p` (3 per point, all points), in the
  // reference's order: sample (iu, iv, iw) at iu + nu_s (iv + nv_s iw).
  //
  // Only the samples whose control points differ (in any bit) from those of the previous call
  // are computed again; the others keep their dets, which the same bits give again. Between
  // two steps of the line search, or two iterations, about 40 % of the duck's samples keep
  // theirs. Not for concurrent calls: the dets of the previous call are kept here.
  void dets(const std::vector<double>& p, std::vector<double>& out) const;

  // F and its gradient (with respect to all points; the caller masks the boundary), from the
  // dets of `p` that dets() gave.
  double value_gradient(const std::vector<double>& p, const std::vector<double>& det, double sigma, double scale,
                        double target, std::vector<double>* grad) const;

 private:
  // The span cells whose points differ from the previous call's (all on the first call).
  void mark_moved(const std::vector<double>& p) const;

  mutable UntangleTables t_;  // `moved` changes with each call of dets()
  int threads_ = 0;
  // The previous call's control points and dets.
  mutable std::vector<double> last_points_, last_det_;
};

}  // namespace trivox::detail
