// Volume: a trivariate with 3D points (polynomial or rational) and the fast evaluators the
// slicer and the inverse map run per voxel: value, and value plus Jacobian in one pass.
// Construction packs the control points as homogeneous (w*x, w*y, w*z, w) rows with periodic
// directions unwrapped, so evaluation is branch-free tensor contraction with no allocation.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {
namespace detail {
struct VolumeData;
struct PowerForm;
}  // namespace detail

// The two fast evaluators behind Volume::evaluate and evaluate_jacobian. Both are checked
// against TensorSpline's general evaluator (the reference) in the tests.
enum class VolumeKernel {
  // Each polynomial piece stored in power form in its local coordinates: no span search
  // beyond a table look-up, no basis recursion. Orders 2 to 4 in every direction only.
  kPowerForm,
  // De Boor-style contraction of the control points with the basis functions: any order.
  kDeBoor,
};

struct VolumeOptions {
  // Use the power form where the orders allow it and its table fits in the cap below.
  bool power_form = true;
  // The power form stores order_u * order_v * order_w homogeneous points per polynomial
  // piece (2 KiB per cubic piece); beyond this size the volume uses the de Boor kernel.
  // The default holds 32768 cubic pieces, a 35 x 35 x 35 control net.
  std::size_t power_form_max_bytes = std::size_t{64} << 20;
};

class Volume {
 public:
  // Throws ModelError unless the spline has param_dim 3 and point_dim 3.
  explicit Volume(TensorSpline spline, const VolumeOptions& options = {});

  // The evaluator chosen at construction.
  VolumeKernel kernel() const noexcept { return power_ ? VolumeKernel::kPowerForm : VolumeKernel::kDeBoor; }

  const TensorSpline& spline() const noexcept { return spline_; }
  const ParamBox& domain() const noexcept { return domain_; }
  std::array<int, 3> orders() const noexcept {
    return {spline_.knots(0).order(), spline_.knots(1).order(), spline_.knots(2).order()};
  }

  // V(u,v,w). Parameters are clamped to the domain.
  Vec3 evaluate(Vec3 uvw) const noexcept;

  // V at several parameters: out[i] = evaluate(uvw[i]), bit for bit. The power form
  // interleaves up to four independent evaluations, so their latencies overlap (for callers
  // with several points whose answers do not depend on each other). out.size() must equal
  // uvw.size().
  void evaluate_many(std::span<const Vec3> uvw, std::span<Vec3> out) const noexcept;

  // V and its Jacobian (column c = dV/d(param c)) in one pass.
  void evaluate_jacobian(Vec3 uvw, Vec3& value, Mat3& jacobian) const noexcept;

  // V and its Jacobian at several parameters: evaluate_jacobian at each, one after the other.
  // The three spans have the same size.
  void evaluate_jacobian_many(std::span<const Vec3> uvw, std::span<Vec3> values,
                              std::span<Mat3> jacobians) const noexcept;

  // Box of all Euclidean control points: contains the whole image.
  const Box3& bounds() const noexcept { return bounds_; }

  // Conservative bounds of the image of a parameter sub-box: the box of the control points
  // whose basis support meets `box` (convex hull property; weights are positive).
  Box3 bounds(const ParamBox& box) const noexcept;

  // For a polynomial volume, M with M(i, j) >= |d^2 V / dt_i dt_j| (Euclidean norm) anywhere
  // in the domain, from the control nets of the second derivatives; empty for a rational
  // one. Taylor's theorem then bounds |V(t + d) - V(t) - J(t) d| by
  // 0.5 * sum_ij |d_i| |d_j| M(i, j), which certifies a Newton step without evaluating V at
  // its end (the tracing fast path of the inverse map).
  const std::optional<Mat3>& second_derivative_bounds() const noexcept { return second_bounds_; }

 private:
  TensorSpline spline_;
  ParamBox domain_;
  Box3 bounds_;
  std::optional<Mat3> second_bounds_;
  std::array<int, 3> num_basis_{};
  // Homogeneous control points, basis-index layout (periodic directions unwrapped), u fastest.
  std::vector<std::array<double, 4>> hpoints_;
  // Kernels specialised for this volume's orders (chosen once, in the constructor).
  Vec3 (*evaluate_fn_)(const detail::VolumeData&, Vec3) noexcept = nullptr;
  void (*evaluate_jacobian_fn_)(const detail::VolumeData&, Vec3, Vec3&, Mat3&) noexcept = nullptr;
  // The power form, when used (immutable, so copies of the volume share it).
  std::shared_ptr<const detail::PowerForm> power_;
  Vec3 (*power_evaluate_fn_)(const detail::PowerForm&, Vec3) noexcept = nullptr;
  void (*power_evaluate_many_fn_)(const detail::PowerForm&, const Vec3*, Vec3*, std::size_t) noexcept = nullptr;
  void (*power_evaluate_jacobian_fn_)(const detail::PowerForm&, Vec3, Vec3&, Mat3&) noexcept = nullptr;
  detail::VolumeData data() const noexcept;
};

}  // namespace trivox
