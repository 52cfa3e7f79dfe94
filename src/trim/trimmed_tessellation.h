// Tessellation of trimmed surfaces (trim.h: TrimmedSurface) for the shell mesh, and the check
// that a shell of trimmed surfaces is closed up to a gap.
#pragma once

#include <array>
#include <vector>

#include "trivox/math.h"
#include "trivox/trim/trim.h"

namespace trivox::detail {

// The point S(a, b) of a surface with 3D points.
inline Vec3 surface_point(const TensorSpline& s, double a, double b) {
  const double t[2] = {a, b};
  double p[3];
  s.evaluate(t, p);
  return {p[0], p[1], p[2]};
}

// The loops of a trimmed surface as closed polygons in its (u, v) (x, y of each point; z 0).
// Throws ModelError naming the surface when a loop does not close.
std::vector<std::vector<Vec3>> trim_loops(const TrimmedSurface& s);

// Appends the part of the surface inside its loops (even-odd) as triangles: the surface's
// n x n grid, each grid triangle crossed by a loop clipped to the loops (Sutherland-Hodgman
// of each loop against the convex triangle, fanned). Counted modulo 2 - the way a ray's
// crossings are - the triangles cover exactly the even-odd interior, and their boundary is
// the loops mapped onto the surface.
void tessellate_trimmed(const TrimmedSurface& s, int n, std::vector<Vec3>& vertices,
                        std::vector<std::array<int, 3>>& triangles);

// Checks that the trimmed surfaces close up: a segment shared by two surfaces must map to
// the same curve in space from both (within `gap`), and a segment on one surface only (a
// seam of a closed surface) must lie within `gap` of another such segment. Returns the
// largest distance found; throws ModelError naming the shell, the surface, the segment and
// the place when one exceeds `gap`.
double check_trimmed_closed(const TrimShell& shell, double gap);

}  // namespace trivox::detail
