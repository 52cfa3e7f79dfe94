// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// The building blocks of traced inversion that the slicer's tracer (slice/cell_tracer.cpp)
// takes from the inverse layer: a first-order prediction from a solved neighbour, Newton
// from it, the check of one Newton step by Taylor's remainder, and the outward direction of
// a point Newton found beyond a face. Declared here so that the wall between the two layers
// is explicit; they are details of the tracing (namespace detail), not a stable API.
// invert() and invert_from_neighbour() (invert.h) are the stable entry points.
#pragma once

#include <optional>

#include "trivox/inverse/invert.h"

namespace trivox::detail {

// The first-order prediction seed + J^-1 (x - seed_x) from a solved neighbour, clamped to the
// domain (the seed itself when J is singular).
inline Vec3 predict_from_seed(const ParamBox& domain, Vec3 x, Vec3 seed_uvw, Vec3 seed_x,
                              const Mat3& seed_jacobian) noexcept {
  Vec3 d;
  return solve3(seed_jacobian, x - seed_x, d, 0.0) ? domain.clamp(seed_uvw + d) : seed_uvw;
}

// Newton from one solved neighbour (invert_from_neighbour, and the slicer's slow path): x is a
// pixel next to `seed_x`, whose solution `seed_uvw` and Jacobian `seed_jacobian` are known.
// Predicts u = seed + J^-1 (x - seed_x), takes one Newton step from there and checks the
// residual (check_newton_step, else a value-only evaluation at the step's end); falls back to
// newton_in_box when that does not meet the tolerance. `jacobian` receives J near the
// solution (for the next prediction). Every converged result meets the residual tolerance.
InverseResult invert_traced(const Volume& volume, Vec3 x, Vec3 seed_uvw, Vec3 seed_x, const Mat3& seed_jacobian,
                            const InverseParams& params, Mat3& jacobian) noexcept;

// x checked against a parameter t where p = V(t) and J = V's Jacobian at t are known: t itself
// when |x - p| meets the tolerance, else the Newton step t + d when it stays in the domain
// and certified_step_residual() places it within the tolerance. Costs no evaluation.
struct NewtonStepCheck {
  bool converged = false;
  Vec3 uvw;              // when converged: t or t + d
  double residual = 0;   // when converged: |x - p|, or the certified bound at t + d
  bool stepped = false;  // not converged, but t + d was solved and lies in the domain
  Vec3 target;           // t + d when stepped
};
NewtonStepCheck check_newton_step(const Volume& volume, Vec3 x, Vec3 t, Vec3 p, const Mat3& J,
                                  const InverseParams& params) noexcept;

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
