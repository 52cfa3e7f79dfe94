// Sweep of a planar section along a space curve, with twist. Approximate: the section is
// placed at `stations` parameters of the path spaced evenly in the path's parameter, in a
// rotation-minimising frame (the double reflection method of Wang, Juttler, Zheng and Liu,
// "Computation of rotation minimizing frames", ACM TOG 2008), turned by the twist; then
// every control point of the section is interpolated through its placements by a cubic
// B-spline in w (knots by averaging, The NURBS Book 9.2.1). The volume passes through the
// placed sections exactly at the stations; between them it deviates from the ideal sweep by
// about the report's approximation_error_mm.
#pragma once

#include <optional>

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct SweepParams {
  // Total rotation of the section about the path's tangent from start to end, added
  // linearly in the path parameter (counter-clockwise looking along the tangent).
  double twist_deg = 0.0;
  int stations = 33;  // >= 4
  // Direction of the section's local x axis at the start of the path (projected onto the
  // plane normal to the tangent); default: the coordinate axis least aligned with the
  // tangent.
  std::optional<Vec3> initial_x;
  JacobianCheckParams check{9};
};

// `section`: a surface in its own plane z = 0 (control points with z = 0; x, y in mm around
// the local origin, which follows the path). `path`: a curve (1 parameter, 3D points). The
// section's local x, y axes go to the frame's normal and binormal, its z axis to the
// path's tangent, so V(u,v,w) = path(w') + x(u,v) N(w') + y(u,v) B(w'), w in [0,1] mapped
// onto the path's domain. A closed path (its ends meet with the same tangent) gets the
// frame's closing rotation spread along it, so that the end section matches the start (with
// a twist, only when the twist is a whole number of turns).
// Throws ModelError on a non-planar section, a path with a zero tangent at a station or
// too few stations.
Constructed sweep(const TensorSpline& section, const TensorSpline& path, const SweepParams& params);

}  // namespace trivox
