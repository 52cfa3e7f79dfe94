// Extrusion of a surface along a vector and the ruled volume between two surfaces. Both are
// exact: the new parameter w is linear (order 2) between the two end faces.
#pragma once

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct ExtrudeParams {
  Vec3 vector_mm{0, 0, 1};  // translation from the face w = 0 to the face w = 1; not zero
  JacobianCheckParams check{9};
};

// V(u,v,w) = S(u,v) + w * vector_mm, w in [0, 1]. `surface`: a surface (2 parameters, 3D
// points), B-spline or NURBS; its (u,v) domain is kept. Throws ModelError on a wrong input.
Constructed extrude(const TensorSpline& surface, const ExtrudeParams& params);

struct RuledParams {
  JacobianCheckParams check{9};
};

// The volume linear in w between `from` (face w = 0) and `to` (face w = 1). The surfaces'
// (u,v) domains are mapped onto [0,1]^2 and made compatible (degree raising and knot
// insertion, exact), so V(u,v,0) = from and V(u,v,1) = to exactly. For polynomial surfaces
// V = (1 - w) from + w to; rational surfaces are blended in homogeneous coordinates.
Constructed ruled(const TensorSpline& from, const TensorSpline& to, const RuledParams& params = {});

}  // namespace trivox
