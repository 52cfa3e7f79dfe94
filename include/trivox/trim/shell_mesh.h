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
// Inside and outside follow the even-odd rule along +x in the plane of constant z, with one
// tie rule everywhere ("a vertex at or above a plane or line counts as above", crossing
// points computed from each edge in a fixed vertex order): two triangles that share an edge
// cut it at bit-identical points, so a point is never counted in or out twice, whatever
// degenerate position it takes. The slicer uses the same cut per layer (cut()) and the same
// crossing rule per row, so its pixels and contains() agree.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "trivox/math.h"
#include "trivox/trim/trim.h"

namespace trivox {

struct ShellSegment {
  double x0, y0, x1, y1;
};

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

  // Edges used by an odd number of triangles (0 for a closed shell).
  std::size_t open_edges() const noexcept { return open_edges_; }
  std::size_t triangle_count() const noexcept { return triangles_.size(); }
  std::size_t vertex_count() const noexcept { return vertices_.size(); }
  int samples() const noexcept { return samples_; }
  const Box3& bounds() const noexcept { return bounds_; }

  // The same mesh with every vertex moved by `map` (for a parametric trim: through the
  // cell's volume, giving its outline in model space). Topology and tie rules are kept.
  ShellMesh mapped(const std::function<Vec3(Vec3)>& map) const;

  // The cross-section at height z: one segment per triangle crossing the plane.
  void cut(double z, std::vector<ShellSegment>& out) const;
  // Every triangle that meets the slab z0 <= z <= z1, once each (its vertices).
  void slab(double z0, double z1, std::vector<std::array<Vec3, 3>>& out) const;
  // Whether p lies inside by the even-odd rule (see above). Thread-safe.
  bool contains(Vec3 p) const;

 private:
  ShellMesh() = default;
  void build_index();
  // The segment where triangle t crosses the plane z; false when it does not.
  bool cut_triangle(int t, double z, ShellSegment& s) const;

  int samples_ = 0;
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::size_t open_edges_ = 0;
  Box3 bounds_;
  // Triangles bucketed by height (cut) and by (y, z) cell (contains).
  double z0_ = 0, dz_ = 1, y0_ = 0, dy_ = 1;
  int nz_ = 1, ny_ = 1;
  std::vector<std::vector<int>> z_buckets_;
  std::vector<std::vector<int>> yz_cells_;
};

// Where the line y = yc crosses a cut segment, by the rule of ShellMesh::contains (each
// endpoint at or above yc counts as above); false when it does not cross.
inline bool crosses_row(const ShellSegment& s, double yc, double& x) noexcept {
  if ((s.y0 >= yc) == (s.y1 >= yc)) return false;
  x = s.x0 + (yc - s.y0) / (s.y1 - s.y0) * (s.x1 - s.x0);
  return true;
}

}  // namespace trivox
