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

// The same for one weighted sum of the components, sum_q weights[q] P[q] (itself a spline
// with those coefficients): the smallest and largest over the same control points.
void coefficient_sum_bounds(const TensorSpline& spline, const ParamBox& box, std::span<const double> weights,
                            double& lo, double& hi);

}  // namespace trivox::detail

namespace trivox::detail {

// The spline restricted to a box of its parameters (clamped to its domain; knots inserted at
// the box's faces), whose control coefficients are the tight hull of that piece; the spline
// itself when the box is degenerate along a direction.
TensorSpline restricted_piece(const TensorSpline& spline, const ParamBox& box);

}  // namespace trivox::detail
