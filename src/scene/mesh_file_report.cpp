// The description of a mesh file (trivox/scene/mesh_file_report.h) and the words for a mesh
// check's failures, which a scene's mesh trim (mesh_trim_parse.cpp) is refused with too.
#include "trivox/scene/mesh_file_report.h"

#include <string>
#include <vector>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/mesh/detail/mesh_check.h"
#include "trivox/mesh/sliced_mesh.h"

namespace trivox {

namespace detail {

namespace {

// "the 18th triangle (corners (x, y, z), ...)": 1-based among the triangles read, with its
// corners in the file's coordinates, which name it whatever a viewer numbers.
std::string describe_triangle(const TriangleMeshFile& f, int t) {
  const auto& tri = f.triangles[static_cast<std::size_t>(t)];
  const Vec3 &a = f.vertices[static_cast<std::size_t>(tri[0])], &b = f.vertices[static_cast<std::size_t>(tri[1])],
             &c = f.vertices[static_cast<std::size_t>(tri[2])];
  return fmt::format(
      "triangle {} of the file, corners ({:.7g}, {:.7g}, {:.7g}), ({:.7g}, {:.7g}, {:.7g}), ({:.7g}, "
      "{:.7g}, {:.7g})",
      t + 1, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z);
}

}  // namespace

std::string mesh_check_report(const TriangleMeshFile& f, const MeshCheck& c, double tolerance_mm) {
  std::vector<std::string> parts;
  if (c.open_edges.count > 0)
    parts.push_back(fmt::format("not closed: {} open edges, each on one triangle only (e.g. {})", c.open_edges.count,
                                describe_triangle(f, c.open_edges.triangle)));
  if (c.nonmanifold_edges.count > 0)
    parts.push_back(fmt::format("not closed: {} non-manifold edges, each on three or more triangles (e.g. {})",
                                c.nonmanifold_edges.count, describe_triangle(f, c.nonmanifold_edges.triangle)));
  if (c.misoriented_edges.count > 0)
    parts.push_back(
        fmt::format("not consistently oriented: {} edges whose two triangles run along them the same "
                    "way, a flipped triangle on one side (e.g. {})",
                    c.misoriented_edges.count, describe_triangle(f, c.misoriented_edges.triangle)));
  if (c.duplicate_triangles.count > 0)
    parts.push_back(fmt::format("doubled: {} triangles repeat the corners of an earlier one (e.g. {}, a repeat of {})",
                                c.duplicate_triangles.count, describe_triangle(f, c.duplicate_triangles.triangle),
                                describe_triangle(f, c.duplicate_triangles.other)));
  if (c.intersections_cut_short && c.self_intersections.count == 0)
    parts.push_back(
        "too crowded to check for self-intersections in bounded time: more pairs of triangles lie close together "
        "than the check looks at (layers of coincident faces, or a fan of many slivers)");
  if (c.self_intersections.count > 0)
    parts.push_back(fmt::format(
        "self-intersecting: {}{} pairs of triangles cross or overlap by more than {:.4g} mm, "
        "the printer's pixel (e.g. {} and {})",
        c.intersections_cut_short ? "at least " : "", c.self_intersections.count, tolerance_mm,
        describe_triangle(f, c.self_intersections.triangle), describe_triangle(f, c.self_intersections.other)));
  std::string all;
  for (std::size_t i = 0; i < parts.size(); ++i) all += fmt::format("{}{}", i == 0 ? "" : "; ", parts[i]);
  return all;
}

}  // namespace detail

MeshFileReport describe_mesh_file(const std::filesystem::path& path, double intersection_tolerance_mm,
                                  const std::atomic<bool>* stop) {
  const TriangleMeshFile f = read_triangle_mesh(path, stop);
  MeshFileReport r;
  r.source = f.source;
  r.format = f.format;
  r.triangles = f.triangles.size();
  r.vertices = f.vertices.size();
  r.dropped_degenerate = f.dropped_degenerate;
  r.ignored_primitives = f.ignored_primitives;
  const SlicedMesh mesh(f.vertices, f.triangles);
  r.bounds = mesh.bounds();
  MeshCheckParams params;
  params.intersection_tolerance = intersection_tolerance_mm;
  params.stop = stop;
  const MeshCheck c = check_mesh(mesh, params);
  r.open_edges = c.open_edges.count;
  r.nonmanifold_edges = c.nonmanifold_edges.count;
  r.misoriented_edges = c.misoriented_edges.count;
  r.self_intersections = c.self_intersections.count;
  r.duplicate_triangles = c.duplicate_triangles.count;
  r.intersections_cut_short = c.intersections_cut_short;
  r.intersection_tolerance_mm = intersection_tolerance_mm;
  r.passed = c.passed();
  if (!r.passed) r.problems = detail::mesh_check_report(f, c, intersection_tolerance_mm);
  return r;
}

}  // namespace trivox
