// Thick shell from a surface: the volume between the surface and its offset along the unit
// normal n = S_u x S_v / |S_u x S_v|. Approximate: the offset surface is represented in the
// surface's own spline space (refined by extra knots, with the surface's weights for a
// NURBS), interpolating the true offset S + d n at the Greville abscissae; the report's
// approximation_error_mm is the largest distance from the true offset found on a sampling
// grid between them. Offsets of concentric circles and of planes are reproduced exactly.
#pragma once

#include <optional>
#include <string_view>

#include "trivox/construct/report.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

enum class ShellSide {
  kOutside,  // from S (w = 0) to S + thickness n (w = 1)
  kInside,   // from S - thickness n (w = 0) to S (w = 1)
  kCentred,  // from S - thickness/2 n to S + thickness/2 n
};

// The side a scene file's "side" or the Python module's `side` names: "outside", "inside",
// "centred" (or "centered"); nothing for any other name (the caller says what it expected).
std::optional<ShellSide> shell_side_from_name(std::string_view name) noexcept;

struct ShellParams {
  double thickness_mm = 1.0;  // > 0
  ShellSide side = ShellSide::kOutside;
  // Knots inserted, evenly spaced, into every non-empty knot span of the surface along both
  // directions before the offset is interpolated (more: a closer offset), 0 to 8.
  int knots_per_span = 1;
  JacobianCheckParams check{9};
};

// `surface`: 2 parameters, 3D points. Throws ModelError when the normal vanishes at an
// interpolation point (a collapsed edge whose neighbourhood gives no normal either).
// Where the thickness exceeds the radius of curvature on the concave side the shell folds;
// the report says where.
Constructed thick_shell(const TensorSpline& surface, const ShellParams& params);

}  // namespace trivox
