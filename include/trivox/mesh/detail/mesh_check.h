// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// The checks a triangle mesh passes before it decides inside and outside by the even-odd
// rule (a mesh trim, trivox/trim/shell_mesh.h), and the repair of its orientation.
//
// Edges are pairs of vertex indices (a mesh from a file is welded where vertices are equal,
// trivox/io/triangle_mesh.h):
//  * closed: every edge is shared by exactly two triangles; an edge of one triangle is open
//    (a gap or a hole), an edge of three or more is non-manifold (sheets meeting along it);
//  * consistently oriented: the two triangles of an edge run along it in opposite
//    directions (a flipped triangle runs along each of its edges the same way as its
//    neighbour);
//  * not self-intersecting at the scale of a pixel: no two triangles that share no edge cross
//    along a segment longer than a tolerance (a pixel), nor overlap in their common plane by
//    a width more than it. Triangles that touch, and nicks shorter than the tolerance, pass.
//  * no duplicates: no triangle has the same three corners as another (in any order): a part
//    exported twice, a face repeated. Each repeat is counted, and left out of the
//    intersection test (every copy would overlap every other).
// Each defect comes with a count and an example: the lowest-numbered triangle involved (and
// for an intersection, the lowest-numbered triangle it crosses; for a duplicate, the earlier
// triangle it repeats), so the report is the same every run.
//
// Time and memory are bounded: the intersection test looks at the pairs of triangles whose
// boxes share a cell of a grid sized by a typical triangle, at most 8 cell entries per
// triangle, and at most `max_pair_tests` pairs; a mesh that needs more (layers of coincident
// faces, a fan of many slivers around one point) is cut short, which the result says, and the
// stop flag is read while it runs.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "trivox/mesh/sliced_mesh.h"

namespace trivox {

struct MeshDefect {
  std::size_t count = 0;  // edges, or pairs of triangles for intersections
  int triangle = -1;      // an example triangle (-1 when count is 0)
  int other = -1;         // intersections: the triangle it crosses
};

struct MeshCheckParams {
  // Intersections shorter (and overlaps narrower) than this, in the mesh's units, pass.
  double intersection_tolerance = 0;
  // Whether to look for intersections at all (the slowest check).
  bool self_intersections = true;
  // Pairs of nearby triangles the intersection test may look at before it stops (the result
  // is then cut short); 0: 256 per triangle, at least 2^28 (some seconds to a minute).
  std::int64_t max_pair_tests = 0;
  // Raised by the caller to stop the check: it then throws CancelledError. May be null.
  const std::atomic<bool>* stop = nullptr;
};

struct MeshCheck {
  MeshDefect open_edges;
  MeshDefect nonmanifold_edges;
  MeshDefect misoriented_edges;
  MeshDefect self_intersections;
  MeshDefect duplicate_triangles;  // count: triangles that repeat an earlier one
  // The intersection test spent its budget of pairs (MeshCheckParams::max_pair_tests) before
  // it looked at all of them: self_intersections counts those found so far, and a mesh cut
  // short does not pass, whatever that count.
  bool intersections_cut_short = false;

  bool closed() const noexcept { return open_edges.count == 0 && nonmanifold_edges.count == 0; }
  bool passed() const noexcept {
    return closed() && misoriented_edges.count == 0 && self_intersections.count == 0 &&
           duplicate_triangles.count == 0 && !intersections_cut_short;
  }
};

MeshCheck check_mesh(const SlicedMesh& mesh, const MeshCheckParams& params);

// Whether two triangles, given by their corners, cross along more than `tolerance` or overlap
// in their common plane by more than it (the test check_mesh applies to each pair that shares
// no edge; shared corners, given as equal points, are not an intersection by themselves).
// Exposed for tests.
bool triangles_intersect(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b, double tolerance);

// Orientation repair: flips triangles so that every edge of exactly two triangles is run along
// in opposite directions, component by component (triangles joined through such edges). In
// each component the orientation that more of the triangles' area already had is kept, so a
// few flipped triangles are turned back and a cavity's inward-facing shell stays inward. A
// component that cannot be oriented (a Moebius strip) keeps the conflicts it has.
// Returns the number of triangles flipped.
std::size_t orient_consistently(const std::vector<Vec3>& vertices, std::vector<SlicedMesh::Triangle>& triangles);

}  // namespace trivox
