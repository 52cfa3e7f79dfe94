// Evaluation kernels of Volume by de Boor's algorithm: the reference evaluator and the one
// for orders above 4 and volumes whose power form would be too large (power_form.h). The
// kernels themselves are in volume_kernels-inl.h, compiled once per SIMD target; these
// functions pick the ones for the given orders on the best target this processor has
// (docs/ARCHITECTURE.md, "SIMD targets").
#pragma once

#include <cstddef>

#include "trivox/math.h"
#include "trivox/spline/detail/homogeneous.h"
#include "trivox/spline/knot_vector.h"

namespace trivox::detail {

struct VolumeData {
  const KnotVector* knots[3];
  const H* points;  // basis-index layout, u fastest
  std::size_t stride_v, stride_w;
};

using EvaluateFn = Vec3 (*)(const VolumeData&, Vec3) noexcept;
using EvaluateJacobianFn = void (*)(const VolumeData&, Vec3, Vec3&, Mat3&) noexcept;

// The kernels for these orders: specialised when every order is 2, 3 or 4, generic otherwise.
EvaluateFn select_evaluate(int ku, int kv, int kw) noexcept;
EvaluateJacobianFn select_evaluate_jacobian(int ku, int kv, int kw) noexcept;

}  // namespace trivox::detail
