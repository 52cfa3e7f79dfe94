// Conservative bounds of a tensor spline over a parameter box, shared by the spline-based
// material kinds: by the convex hull property (non-negative basis functions summing to 1,
// positive NURBS weights), the value at any parameter in the box lies between the smallest
// and largest control coefficient whose basis function is non-zero somewhere in the box.
#pragma once

#include <span>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::detail {

// lo and hi get point_dim values each. `box` is in the spline's parameters; it is clamped to
// the domain first.
void coefficient_bounds(const TensorSpline& spline, const ParamBox& box, std::span<double> lo, std::span<double> hi);

}  // namespace trivox::detail
