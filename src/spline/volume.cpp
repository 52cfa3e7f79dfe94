#include "trivox/spline/volume.h"

#include <algorithm>

#include <fmt/format.h>

#include "derivative_bounds.h"
#include "power_form.h"
#include "trivox/error.h"
#include "trivox/spline/detail/basis.h"
#include "volume_kernels.h"

namespace trivox {

using detail::H;

Volume::Volume(TensorSpline spline, const VolumeOptions& options) : spline_(std::move(spline)) {
  if (spline_.param_dim() != 3 || spline_.point_dim() != 3)
    throw ModelError(fmt::format("a volume needs 3 parametric directions and 3D points, got {} and {}",
                                 spline_.param_dim(), spline_.point_dim()));
  for (int d = 0; d < 3; ++d) num_basis_[static_cast<std::size_t>(d)] = spline_.knots(d).num_basis();
  domain_ = ParamBox{{spline_.lo(0), spline_.lo(1), spline_.lo(2)}, {spline_.hi(0), spline_.hi(1), spline_.hi(2)}};
  hpoints_.resize(static_cast<std::size_t>(num_basis_[0] * num_basis_[1] * num_basis_[2]));
  std::size_t n = 0;
  for (int k = 0; k < num_basis_[2]; ++k)
    for (int j = 0; j < num_basis_[1]; ++j)
      for (int i = 0; i < num_basis_[0]; ++i) {
        const int ci = spline_.knots(0).ctrl_index(i), cj = spline_.knots(1).ctrl_index(j),
                  ck = spline_.knots(2).ctrl_index(k);
        const auto p = spline_.point(ci, cj, ck);
        const double w = spline_.weight(ci, cj, ck);
        hpoints_[n++] = {w * p[0], w * p[1], w * p[2], w};
      }
  bounds_ = spline_.control_box();
  second_bounds_ = detail::second_derivative_bounds(spline_);
  const auto k = orders();
  evaluate_fn_ = detail::select_evaluate(k[0], k[1], k[2]);
  evaluate_jacobian_fn_ = detail::select_evaluate_jacobian(k[0], k[1], k[2]);
  if (options.power_form) {
    auto power = std::make_shared<detail::PowerForm>();
    if (detail::build_power_form(data(), *power, options.power_form_max_bytes)) {
      power_ = std::move(power);
      power_evaluate_fn_ = detail::select_power_evaluate(k[0], k[1], k[2]);
      power_evaluate_many_fn_ = detail::select_power_evaluate_many(k[0], k[1], k[2]);
      power_evaluate_jacobian_fn_ = detail::select_power_evaluate_jacobian(k[0], k[1], k[2]);
    }
  }
}

detail::VolumeData Volume::data() const noexcept {
  const auto nu = static_cast<std::size_t>(num_basis_[0]);
  return {{&spline_.knots(0), &spline_.knots(1), &spline_.knots(2)},
          hpoints_.data(),
          nu,
          nu * static_cast<std::size_t>(num_basis_[1])};
}

Vec3 Volume::evaluate(Vec3 uvw) const noexcept {
  if (power_) return power_evaluate_fn_(*power_, uvw);
  return evaluate_fn_(data(), uvw);
}

void Volume::evaluate_many(std::span<const Vec3> uvw, std::span<Vec3> out) const noexcept {
  if (power_) return power_evaluate_many_fn_(*power_, uvw.data(), out.data(), uvw.size());
  const detail::VolumeData d = data();
  for (std::size_t i = 0; i < uvw.size(); ++i) out[i] = evaluate_fn_(d, uvw[i]);
}

void Volume::evaluate_jacobian(Vec3 uvw, Vec3& value, Mat3& jacobian) const noexcept {
  if (power_) return power_evaluate_jacobian_fn_(*power_, uvw, value, jacobian);
  evaluate_jacobian_fn_(data(), uvw, value, jacobian);
}

void Volume::evaluate_jacobian_many(std::span<const Vec3> uvw, std::span<Vec3> values,
                                    std::span<Mat3> jacobians) const noexcept {
  // One point after the other: interleaving value-and-Jacobian evaluations, as evaluate_many
  // does for values, needs more registers than the machine has and measured slower
  // (kernel_bench BM_EvaluateRowChains, modes 3 and 4).
  for (std::size_t i = 0; i < uvw.size(); ++i) evaluate_jacobian(uvw[i], values[i], jacobians[i]);
}

Box3 Volume::bounds(const ParamBox& box) const noexcept {
  // Basis functions whose support [t_i, t_{i+k}) meets [lo, hi] along each direction.
  std::array<int, 3> i0{}, i1{};
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline_.knots(d);
    const double lo = std::clamp(box.lo[d], kv.lo(), kv.hi());
    const double hi = std::clamp(box.hi[d], kv.lo(), kv.hi());
    i0[static_cast<std::size_t>(d)] = kv.find_span(lo) - kv.degree();
    i1[static_cast<std::size_t>(d)] = kv.find_span(hi);
  }
  Box3 out;
  const auto nu = static_cast<std::size_t>(num_basis_[0]);
  const auto nuv = nu * static_cast<std::size_t>(num_basis_[1]);
  for (int k = i0[2]; k <= i1[2]; ++k)
    for (int j = i0[1]; j <= i1[1]; ++j)
      for (int i = i0[0]; i <= i1[0]; ++i) {
        const H& h = hpoints_[static_cast<std::size_t>(k) * nuv + static_cast<std::size_t>(j) * nu +
                              static_cast<std::size_t>(i)];
        out.expand(Vec3{h[0] / h[3], h[1] / h[3], h[2] / h[3]});
      }
  return out;
}

}  // namespace trivox
