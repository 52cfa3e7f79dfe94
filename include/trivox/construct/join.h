// One B-spline surface from a grid of surfaces that meet edge to edge, such as the bicubic
// Bezier patches of the Utah teapot: the input to a constructor that needs a single face
// (a thick shell of a whole teapot body rather than one shell per patch). Exact: the patches
// are made compatible (domains onto [0,1]^2, degree raising, knot insertion) and their
// control nets concatenated, the shared boundary rows kept once. Patch (row r, column c)
// becomes the part [c, c + 1] x [r, r + 1] of the joined domain; at the joints the surface
// is C0 (knots of full multiplicity minus one), as the patches themselves only meet there.
#pragma once

#include <vector>

#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct JoinParams {
  // Neighbouring patches share an edge when their (homogeneous) control points along it
  // agree within this fraction of the grid's control-box diagonal.
  double edge_tolerance_relative = 1e-9;
};

// `grid[r][c]`: the patch in row r (along v) and column c (along u); every row has the same
// number of patches, each a surface with 3D points, B-spline or NURBS, whose u runs along
// the row and v along the column. The u = 1 edge of patch (r, c) must be the u = 0 edge of
// (r, c + 1), and its v = 1 edge the v = 0 edge of (r + 1, c), with the same
// parametrization. Throws ModelError naming the two patches (by row and column) and the
// edge when they do not meet, and when the grid is empty or ragged.
TensorSpline join_surfaces(const std::vector<std::vector<TensorSpline>>& grid, const JoinParams& params = {});

}  // namespace trivox
