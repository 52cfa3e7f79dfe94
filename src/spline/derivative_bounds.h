// Bounds of a polynomial volume's second derivatives over its whole domain, for certifying a
// Newton step without evaluating V again (Taylor's theorem with the remainder bounded).
#pragma once

#include <array>
#include <optional>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::detail {

// M(i, j) >= max over the domain of |d^2 V / dt_i dt_j| (Euclidean norm), from the control
// nets of the second partial derivatives: the derivative of a B-spline is a B-spline whose
// control points are scaled differences of the original ones, and on the domain it is a
// convex combination of them, so the largest control-point norm bounds it (NURBS Book,
// Section 3.3). Periodic and unclamped knot vectors work the same way on the full basis.
// Rational volumes get no bound (the quotient rule has no such simple net): nullopt.
std::optional<Mat3> second_derivative_bounds(const TensorSpline& spline);

}  // namespace trivox::detail
