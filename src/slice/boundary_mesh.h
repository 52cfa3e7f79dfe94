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
#include <atomic>
#include <cstdint>

#include "trivox/mesh/sliced_mesh.h"
#include "trivox/spline/volume.h"

namespace trivox::detail {

struct BoundaryMesh {
  SlicedMesh mesh;
  std::array<int, 3> samples{};  // parameters sampled per direction
  // The largest deviation measured between the faces and the mesh (at the grid cells'
  // centres and diagonals): at most the tolerance asked for, unless the budget stopped the
  // refinement first.
  double deviation_mm = 0;
};

// Vertices a mesh sampled `samples` per direction has at most (the six faces' grids).
std::int64_t boundary_mesh_vertices(const std::array<int, 3>& samples) noexcept;
// Bytes a boundary mesh takes per vertex at most while it is built and kept (the vertex, two
// triangles, their height buckets and the builder's tables).
inline constexpr std::int64_t kBoundaryMeshBytesPerVertex = 128;

// Refines the sampling until every grid cell of every face deviates from its bilinear patch
// and from its two triangles by at most `tolerance_mm` at its centre, or until refining
// further would take the mesh past `max_vertices` (then deviation_mm says how close it came;
// the sampling starts coarser than a few samples per polynomial piece when that alone would
// pass the budget). Its time and memory are therefore bounded by the budget, whatever the
// volume's weights, coordinates or the tolerance. Checks `stop` between rounds and throws
// CancelledError once it is raised.
BoundaryMesh build_boundary_mesh(const Volume& volume, double tolerance_mm, std::int64_t max_vertices,
                                 const std::atomic<bool>* stop = nullptr);

}  // namespace trivox::detail
