// Damped Newton on V(u,v,w) = x inside a parameter box: the shared core of invert() and of
// the global solver's leaf step.
#pragma once

#include "trivox/inverse/invert.h"

namespace trivox::detail {

InverseResult newton_in_box(const Volume& volume, Vec3 x, Vec3 start, const ParamBox& box,
                            const InverseParams& params) noexcept;

// The slicer's hot path: x is a pixel next to `seed_x`, whose solution `seed_uvw` and Jacobian
// `seed_jacobian` are known. Predicts u = seed + J^-1 (x - seed_x), takes one Newton step from
// there and checks the residual with a value-only evaluation; falls back to newton_in_box
// when that does not meet the tolerance. `jacobian` receives J near the solution (for the
// next prediction). Every converged result meets the residual tolerance.
InverseResult invert_traced(const Volume& volume, Vec3 x, Vec3 seed_uvw, Vec3 seed_x, const Mat3& seed_jacobian,
                            const InverseParams& params, Mat3& jacobian) noexcept;

}  // namespace trivox::detail
