// Volume of revolution of a surface about an axis, exact and rational (The NURBS Book,
// Section 8.5, A8.1: each control point of the profile sweeps a rational quadratic circular
// arc of at most 90 degrees per segment, weights multiplied by cos(half the segment angle)
// at the middle points).
#pragma once

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct RevolveParams {
  Vec3 axis_point_mm{0, 0, 0};
  Vec3 axis_dir{0, 0, 1};    // not zero; need not be a unit vector
  double angle_deg = 360.0;  // in (0, 360], counter-clockwise looking down axis_dir
  // The parametric direction of the angle: 2 (w, default) makes V(u,v,w) = profile(u,v)
  // turned by w * angle_deg, w in [0, 1]; 0 makes it V(angle, u, v), 1 V(u, angle, v). The
  // orientation (sign of det J) flips with the direction and the profile's orientation.
  int angle_direction = 2;
  JacobianCheckParams check{9};
};

// `profile`: a surface (2 parameters, 3D points), B-spline or NURBS. Control points on the
// axis collapse their arcs to a point: the volume is then degenerate there (det J = 0 on
// the axis), which the report shows.
Constructed revolve(const TensorSpline& profile, const RevolveParams& params);

}  // namespace trivox
