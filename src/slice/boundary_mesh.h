// The boundary of a cell (the six faces of its trivariate) as a watertight triangle mesh,
// built once per cell and cut by every layer's plane into the cell's outline.
//
// Watertight by construction: each parametric direction d is sampled at one set of n_d
// parameters shared by every face, so two faces that meet along an edge of the volume
// evaluate V at the same parameters there and get bit-identical vertices, and the faces'
// tables of vertex numbers make them share the vertex indices too (the tie rule of
// sliced_mesh.h then cuts shared edges identically).
#pragma once

#include <array>

#include "trivox/mesh/sliced_mesh.h"
#include "trivox/spline/volume.h"

namespace trivox::detail {

struct BoundaryMesh {
  SlicedMesh mesh;
  std::array<int, 3> samples{};  // parameters sampled per direction
};

// Refines the sampling until every grid cell of every face deviates from its bilinear patch
// and from its two triangles by at most `tolerance_mm` at its centre (or a direction reaches
// 4096 samples).
BoundaryMesh build_boundary_mesh(const Volume& volume, double tolerance_mm);

}  // namespace trivox::detail
