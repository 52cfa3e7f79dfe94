// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// A closed trimming shell (trim.h) as a watertight triangle mesh, and the point-in-solid
// test on it.
//
// Watertight by construction: every surface is sampled at the same number of uniformly
// spaced parameters in both directions, so two surfaces that share an edge, parametrized
// alike, evaluate it at the same parameters; the samples are then welded (merged when they
// lie within a tiny distance of each other, 1e-9 of the shell's size), which makes shared
// edges share vertex indices. A shell whose welded mesh still has an edge used by an odd
// number of triangles is open, and inside and outside would not be defined.
//
// The mesh itself is a SlicedMesh (trivox/mesh/sliced_mesh.h). Inside and outside follow the
// even-odd rule along +x in the plane of constant z, with the SlicedMesh's tie rule ("a vertex
// at or above a plane or line counts as above", crossing points computed from each edge in a
// fixed vertex order): two triangles that share an edge cut it at bit-identical points, so a
// point is never counted in or out twice, whatever degenerate position it takes. The slicer
// uses the same cut per layer (mesh().cut()) and the same crossing rule per row
// (crosses_row), so its pixels and contains() agree.
//
// A shell with trimmed surfaces (an IRIT MODEL) cannot be welded: its surfaces meet only
// within the accuracy of their trimming curves, so its mesh has hairline gaps along the
// seams. Such a mesh is "gap tolerant": the constructor checks that every seam closes within
// 1e-3 of the shell's size (and throws ModelError naming the surface and the segment
// otherwise), and contains() votes: it counts the crossings of the whole line through p in
// the plane of constant z along x, then along y and the two diagonals, and the first line
// crossed an even number of times decides by the parity beyond p. A line through a gap
// is crossed an odd number of times and loses its vote, so a point is misjudged only when
// all four lines pass through gaps, that is within the gap's width of the surface. The
// slicer does the same: a row crossed an odd number of times asks contains() per pixel.
//
// A mesh trim (TrimShell::mesh) is taken as it is, its triangles and vertices unchanged, and
// decided by its rule. By the even-odd rule it is one more closed mesh, decided as above. By
// the winding-number rule a point is inside when the mesh's generalized winding number there
// (the solid angle its triangles subtend, over 4 pi: Jacobson et al. 2013) is at least 1/2.
// The orientation is repaired first (mesh_check.h: orient_consistently), and the whole mesh
// turned if it then encloses a negative volume. That number is not summed over every
// triangle per pixel: the mesh's boundary (edges used more often one way than the other) is
// closed by a cone of triangles over each of its connected pieces, from the mean of its
// vertices, which makes the mesh and the cones a closed surface; its winding number W is an
// integer counted by signed crossings exactly as the even-odd rule counts crossings
// (crossing_winding, on the same cut: the cones are part of the mesh), and the generalized
// winding number is W minus the cones' own. The cones' share is summed only near them: away
// from a cone its size bounds its share (its area over 4 pi times the squared distance from
// its bounding ball), and where all shares together stay below 1/2 the answer is W >= 1. A
// closed mesh has no cone, and the rule is then the nonzero rule for outward triangles.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "trivox/math.h"
#include "trivox/mesh/sliced_mesh.h"
#include "trivox/trim/trim.h"

namespace trivox {

class ShellMesh {
 public:
  // Samples every surface until each grid cell deviates from its bilinear patch and from its
  // two triangles by at most
  // `tolerance` at its centre (in the shell's units: mm for a model-space shell), or the
  // sample count reaches `max_samples` per direction. Throws ModelError when a surface is
  // not a surface in space (two parameters, three coordinates).
  ShellMesh(const TrimShell& shell, double tolerance, int max_samples = 1024);
  // The same, refined further until the mesh mapped through `map` (vertex by vertex, as
  // mapped() does) deviates from the map of the tessellated surfaces by at most
  // `map_tolerance` at the same test points: a parametric trim's tessellation whose image
  // through the cell's volume is the trim's outline in model space within `map_tolerance`
  // mm, so the pixels it decides inside lie inside that outline.
  ShellMesh(const TrimShell& shell, double tolerance, const std::function<Vec3(Vec3)>& map, double map_tolerance,
            int max_samples = 1024);
  // A mesh trim (shell.mesh set): the mesh as it is, decided by shell.rule. Throws ModelError
  // for an empty mesh.
  explicit ShellMesh(const TrimShell& shell);

  // Whether the shell has trimmed surfaces and is decided by the vote above.
  bool gap_tolerant() const noexcept { return gap_tolerant_; }
  // The largest distance between the two sides of a seam (0 unless gap tolerant).
  double seam_gap() const noexcept { return seam_gap_; }
  // Edges used by an odd number of triangles (0 for a closed shell; not counted for a gap
  // tolerant one, which is checked by its seams).
  std::size_t open_edges() const noexcept { return open_edges_; }
  std::size_t triangle_count() const noexcept { return mesh_.triangle_count(); }
  std::size_t vertex_count() const noexcept { return mesh_.vertex_count(); }
  int samples() const noexcept { return samples_; }
  const Box3& bounds() const noexcept { return mesh_.bounds(); }
  // The triangles, their height buckets, cut() and slab().
  const SlicedMesh& mesh() const noexcept { return mesh_; }

  // The same mesh with every vertex moved by `map` (for a parametric trim: through the
  // cell's volume, giving its outline in model space). Topology and tie rules are kept.
  ShellMesh mapped(const std::function<Vec3(Vec3)>& map) const;

  // Whether p lies inside by the shell's rule (see above). Thread-safe.
  bool contains(Vec3 p) const;

  // Whether the shell is decided by the generalized winding number (a mesh trim's
  // winding-number rule).
  bool winding() const noexcept { return winding_; }
  // The decision of the winding-number rule at p, given w, the sum of crossing_winding over
  // the crossings beyond p.x of the line through p along x in the plane z = p.z with the cut
  // of mesh() (cones included).
  bool winding_inside(int w, Vec3 p) const;
  // The generalized winding number of the mesh's own triangles at p (without the cones),
  // summed over every triangle: the slow reference of winding_inside.
  double generalized_winding_number(Vec3 p) const;
  // The cones that close the boundary, and the triangles flipped by the repair.
  std::size_t cone_count() const noexcept { return cones_.size(); }
  std::size_t flipped_triangles() const noexcept { return flipped_; }

 private:
  ShellMesh() = default;
  // Makes mesh_ from the vertices and triangles, and the (y, z) cells of contains().
  void build_index(std::vector<Vec3> vertices, std::vector<SlicedMesh::Triangle> triangles);
  void build_trimmed(const TrimShell& shell, double tolerance, const std::function<Vec3(Vec3)>* map,
                     double map_tolerance, int max_samples);

  void build_mesh_trim(const SlicedMesh& mesh, InsideRule rule);
  // cones_ and their bounds from the cone triangles of mesh_ (after it moved).
  void bound_cones();
  // The generalized winding number of cone k's triangles at p.
  double cone_winding_number(std::size_t k, Vec3 p) const;
  // The crossings beyond p of the line through p along x in the plane z = p.z: their count
  // and the sum of their windings.
  void row_crossings(Vec3 p, int& beyond, int& winding) const;

  // Parity of the crossings beyond p of the line through p along (dx, dy) in the plane z =
  // p.z; false in `even` when the whole line is crossed an odd number of times.
  bool line_parity(Vec3 p, double dx, double dy, bool& even) const;
  int samples_ = 0;
  bool gap_tolerant_ = false;
  double seam_gap_ = 0;
  std::size_t open_edges_ = 0;
  SlicedMesh mesh_;
  // The winding-number rule: the cones (triangles [first, end) of mesh_, which the mesh's own
  // triangles precede) with a ball holding each, and one ball holding them all.
  struct Cone {
    int first = 0, end = 0;
    Vec3 centre;
    double radius = 0, area = 0;
  };
  bool winding_ = false;
  std::size_t flipped_ = 0;
  int own_triangles_ = 0;
  std::vector<Cone> cones_;
  Cone all_cones_;
  // Triangles by (y, z) cell, for contains(): ny_ x ny_ cells over the mesh's box.
  double z0_ = 0, dzc_ = 1, y0_ = 0, dy_ = 1;
  int ny_ = 1;
  std::vector<std::vector<int>> yz_cells_;
  // The cell of (y, z), clamped to the grid.
  std::size_t yz_cell(double y, double z) const noexcept;
};

}  // namespace trivox
