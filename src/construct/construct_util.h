// Shared steps of the volume constructors: input checks, compatible spline spaces, stacking
// layers of control points into a volume, and the final Jacobian report.
#pragma once

#include <string>
#include <vector>

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::detail {

// `s` clamped, after checking it is a surface with 3D points; `role` names it in errors.
TensorSpline checked_surface(const TensorSpline& s, const std::string& role);

// A spline's direction: entry `dirs[i]` of `splines[i]`. Maps every such direction's domain
// onto [0, 1] and re-expresses them all in one clamped space: the highest order (at least
// `min_order`) and, per interior knot, the largest multiplicity needed. Exact.
struct SplineDir {
  TensorSpline* spline;
  int dir;
};
void make_compatible(const std::vector<SplineDir>& group, int min_order = 1);

// The volume whose control layer k along w is the control net of layers[k]; all layers
// share their knot vectors (and rationality). `w_knots` has layers.size() basis functions.
TensorSpline stack_layers(const std::vector<TensorSpline>& layers, const KnotVector& w_knots);

// The Volume and its report (Jacobian regions), for a finished construction.
Constructed finish(const std::string& constructor, TensorSpline spline, const JacobianCheckParams& check,
                   bool exact = true, double approximation_error_mm = 0.0);

inline Vec3 to_vec3(std::span<const double> p) { return {p[0], p[1], p[2]}; }

// A unit vector along v; throws ModelError with `what` when v is zero or not finite.
Vec3 unit(Vec3 v, const std::string& what);

}  // namespace trivox::detail
