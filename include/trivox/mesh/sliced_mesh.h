// A triangle mesh cut by horizontal planes: the one mesh type behind a cell's outline
// (slice/boundary_mesh.h), a trimming shell (trim/detail/shell_mesh.h) and any closed triangle
// mesh used as a trim.
//
// Coordinates are model space (mm) for outlines and model-space shells, or parameter space
// (u, v, w) for a parametric trim before it is mapped through its cell's volume; the mesh
// does not care which, as long as z is the direction of the cutting planes.
//
// The cut follows one tie rule everywhere: a vertex at or above the plane counts as above,
// and a crossing point is computed from its edge's two vertices in a fixed order (lower
// index first). Two triangles that share an edge (share its two vertex indices) therefore
// cut it at bit-identical points, and an even-odd scan of the segments never counts a
// crossing twice or misses one, whatever degenerate position a vertex takes.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "trivox/math.h"

namespace trivox {

// A segment of a layer's cut, in the plane of the layer (x, y).
struct Segment2 {
  double x0, y0, x1, y1;
};

// Where the line y = yc crosses segment s by the tie rule above (an endpoint at or above yc
// counts as above); false when it does not cross. Every scan of a cut uses this rule, so
// the pixels the slicer keeps and a point-in-solid test on the same mesh agree.
inline bool crosses_row(const Segment2& s, double yc, double& x) noexcept {
  if ((s.y0 >= yc) == (s.y1 >= yc)) return false;
  x = s.x0 + (yc - s.y0) / (s.y1 - s.y0) * (s.x1 - s.x0);
  return true;
}

// The winding contribution of a crossing of the line y = yc by segment s (crosses_row),
// counted for a point left of it (the ray along +x): +1 where the oriented segment runs
// towards -y, -1 where it runs towards +y. `direction` is the segment's direction from
// SlicedMesh::cut_triangle (+1: from (x0, y0) to (x1, y1)). For a closed mesh of
// counter-clockwise triangles (seen from outside) the contributions beyond a point add up to
// its winding number: 1 inside, 0 outside.
inline int crossing_winding(const Segment2& s, int direction) noexcept {
  return (s.y1 < s.y0) == (direction > 0) ? 1 : -1;
}

class SlicedMesh {
 public:
  using Triangle = std::array<int, 3>;

  SlicedMesh() = default;
  // Takes the vertices and the triangles (indices into the vertices, any orientation) and
  // buckets the triangles by height. Indices must lie in [0, vertices.size()).
  SlicedMesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles);

  const std::vector<Vec3>& vertices() const noexcept { return vertices_; }
  const std::vector<Triangle>& triangles() const noexcept { return triangles_; }
  std::size_t vertex_count() const noexcept { return vertices_.size(); }
  std::size_t triangle_count() const noexcept { return triangles_.size(); }
  bool empty() const noexcept { return triangles_.empty(); }
  // The box of the vertices (empty for an empty mesh).
  const Box3& bounds() const noexcept { return bounds_; }

  // The cross-section at height z: one segment per triangle crossing the plane, in triangle
  // order. Replaces the contents of `out`.
  void cut(double z, std::vector<Segment2>& out) const;
  // The same with each segment's direction (below), in `directions`.
  void cut(double z, std::vector<Segment2>& out, std::vector<int>& directions) const;
  // The segment where triangle `t` crosses the plane z; false when it does not.
  bool cut_triangle(int t, double z, Segment2& s) const;
  // The same, with the segment's direction: +1 when the triangle's boundary, followed in its
  // vertex order, rises through the plane at (x0, y0) and falls at (x1, y1), -1 the other way
  // round. Seen from +z, a counter-clockwise triangle (outward normal) then has the solid on
  // the right of its segment run from the rising point to the falling one. The points are
  // those of the call without a direction, bit for bit.
  bool cut_triangle(int t, double z, Segment2& s, int& direction) const;
  // The triangles that may cross the plane z (a superset of those that do).
  std::span<const int> near(double z) const;
  // Every triangle that meets the slab z0 <= z <= z1, once each (its vertices).
  void slab(double z0, double z1, std::vector<std::array<Vec3, 3>>& out) const;

  // The same mesh with every vertex moved by `map`; the triangles (and so the tie rule's
  // vertex order) are kept.
  SlicedMesh mapped(const std::function<Vec3(Vec3)>& map) const;

  // Edges used by an odd number of triangles: 0 for a closed mesh (every edge shared by two
  // triangles, or by an even number where surfaces meet along a seam).
  std::size_t odd_edges() const;

 private:
  int bucket_of(double z) const noexcept;

  std::vector<Vec3> vertices_;
  std::vector<Triangle> triangles_;
  Box3 bounds_;
  // Triangles bucketed by height, so that a cut tests only those near its plane.
  double z0_ = 0, dz_ = 1;
  std::vector<std::vector<int>> buckets_;
};

}  // namespace trivox
