// What a triangle mesh file holds and whether it passes the checks of a mesh trim, for a
// person setting one up (`trivox info bunny.stl`): its format, counts and box, and the checks
// an even-odd mesh trim must pass (docs/SCENE.md, "Mesh trims"), in the words a scene that
// uses the mesh is refused with.
#pragma once

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <string>

#include "trivox/math.h"

namespace trivox {

struct MeshFileReport {
  std::string source;  // the file, as given
  std::string format;  // "binary STL", "ASCII STL", "OBJ", "PLY" or "3MF"
  std::size_t triangles = 0, vertices = 0;
  std::size_t dropped_degenerate = 0;  // triangles that repeated a vertex
  std::size_t ignored_primitives = 0;  // points and lines
  Box3 bounds;                         // of the vertices, in the file's millimetres
  // The checks (each a count of edges, or of triangles for duplicates, or of pairs for
  // intersections); closed: no open and no non-manifold edge.
  std::size_t open_edges = 0, nonmanifold_edges = 0, misoriented_edges = 0;
  std::size_t self_intersections = 0, duplicate_triangles = 0;
  bool intersections_cut_short = false;  // too crowded to finish the intersection test
  double intersection_tolerance_mm = 0;
  bool closed() const noexcept { return open_edges == 0 && nonmanifold_edges == 0; }
  // What the even-odd rule needs; a mesh that fails can still trim by "winding-number".
  bool passed = false;
  // The failed checks, each with an example triangle, as a scene's refusal words them; empty
  // when passed.
  std::string problems;
};

// Reads the mesh file (trivox/io/triangle_mesh.h) and checks it as a mesh trim is checked,
// with intersections shorter than `intersection_tolerance_mm` let pass (a scene uses its
// printer's pixel). Throws as read_triangle_mesh does; `stop` as there, and during the checks.
MeshFileReport describe_mesh_file(const std::filesystem::path& path, double intersection_tolerance_mm,
                                  const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
