// Damped Newton on V(u,v,w) = x inside a parameter box: the shared core of invert() and of
// the global solver's leaf step.
#pragma once

#include <optional>

#include "trivox/inverse/invert.h"

namespace trivox::detail {

InverseResult newton_in_box(const Volume& volume, Vec3 x, Vec3 start, const ParamBox& box,
                            const InverseParams& params) noexcept;

// The slicer's hot path: x is a pixel next to `seed_x`, whose solution `seed_uvw` and Jacobian
// `seed_jacobian` are known. Predicts u = seed + J^-1 (x - seed_x), takes one Newton step from
// there and checks the residual - by the Taylor certificate below when the volume has
// second-derivative bounds and the step is small enough, else with a value-only evaluation;
// falls back to newton_in_box when that does not meet the tolerance. `jacobian` receives J near the solution (for the
// next prediction). Every converged result meets the residual tolerance.
InverseResult invert_traced(const Volume& volume, Vec3 x, Vec3 seed_uvw, Vec3 seed_x, const Mat3& seed_jacobian,
                            const InverseParams& params, Mat3& jacobian) noexcept;

// An upper bound of |V(t + d) - x| for the Newton step d from t, where p = V(t), J = V's
// Jacobian at t and r0 = x - p, without evaluating V at t + d (which must lie in the
// domain): the linear model's leftover plus Taylor's remainder bounded by
// Volume::second_derivative_bounds(). nullopt for a volume without bounds (rational).
std::optional<double> certified_step_residual(const Volume& volume, Vec3 p, const Mat3& J, Vec3 r0, Vec3 d) noexcept;

// For x that Newton found beyond a face of the domain, stopping at `uvw` on that face: the
// face's normal at uvw turned towards x (the cross product of the two tangent columns of
// J), or x - V(uvw) when uvw lies on an edge or corner. A hint for GlobalSolver::solve's
// separating plane; nullopt when the direction vanishes.
std::optional<Vec3> outward_hint(const Volume& volume, Vec3 x, Vec3 uvw) noexcept;

}  // namespace trivox::detail
