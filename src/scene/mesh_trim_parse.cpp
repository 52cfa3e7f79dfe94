// Mesh trims (docs/SCENE.md, "Mesh trims"): a shell {"mesh": F, "placement", "inside_rule"}
// read from a triangle mesh file, placed, and checked before the even-odd rule decides by it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/mesh/detail/mesh_check.h"

namespace trivox::detail {

const TriangleMeshFile& SceneContext::triangle_mesh(const JsonView& file_field) {
  const std::filesystem::path path = existing_file(file_field, "mesh file");
  const std::string key = path.string();
  if (const auto it = meshes_.find(key); it != meshes_.end()) return it->second;
  try {
    // Hashed before it is read, as model files are.
    std::string digest = sha256_file(path, stop()).sha256;
    const TriangleMeshFile& mesh = meshes_.emplace(key, read_triangle_mesh(path, stop())).first->second;
    input_files_.push_back(SceneInputFile{file_field.string(), std::move(digest)});
    return mesh;
  } catch (const CancelledError&) {
    throw;  // a stop is no fault of the file
  } catch (const UnsupportedError& e) {
    throw UnsupportedError(source_, 0, file_field.pointer(),
                           fmt::format("the mesh file \"{}\" cannot be read: {}", file_field.string(), e.what()));
  } catch (const Error& e) {
    file_field.fail(fmt::format("cannot use the mesh file \"{}\": {}", file_field.string(), e.what()));
  }
}

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

std::string mesh_report(const TriangleMeshFile& f, const MeshCheck& c, double tolerance_mm) {
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

// The placed mesh's coordinates overflow, or lie so far out that doubles there are spaced more
// than a thousandth of a pixel apart (the rule refuse_without_interior applies to volumes):
// its triangles would collapse or cross by rounding, so the mesh is refused as what it is,
// not later as self-intersecting.
void refuse_imprecise(const std::vector<Vec3>& vertices, const JsonView& file, double pixel_mm) {
  double far = 0;
  for (const Vec3& v : vertices) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      file.fail(fmt::format("the mesh \"{}\" overflows where it is placed: a corner comes to ({}, {}, {}) mm",
                            file.string(), v.x, v.y, v.z));
    far = std::max(far, max_abs(v));
  }
  const double spacing = far * std::numeric_limits<double>::epsilon();
  if (!(spacing <= 1e-3 * pixel_mm))
    file.fail(
        fmt::format("the mesh \"{}\" lies {:.4g} mm from the origin where it is placed, where doubles are "
                    "{:.4g} mm apart, more than a thousandth of the pixel ({:.4g} mm): its coordinates lose "
                    "the precision its triangles need",
                    file.string(), far, spacing, pixel_mm));
}

}  // namespace

std::shared_ptr<const TrimShell> parse_mesh_shell(const JsonView& node, SceneContext& ctx, std::string_view what) {
  node.expect_object({"mesh", "placement", "inside_rule"});
  const JsonView file = node.at("mesh");
  if (what != "model-space")
    file.fail(
        "a triangle mesh trims in model space: give it as a \"shell\" (a parametric trim is a set of surfaces in "
        "(u, v, w))");
  InsideRule rule = InsideRule::kEvenOdd;
  if (const auto r = node.find("inside_rule")) {
    if (r->string() == "winding-number")
      rule = InsideRule::kWindingNumber;
    else if (r->string() != "even-odd")
      r->fail(fmt::format("expected \"even-odd\" or \"winding-number\", got \"{}\"", r->string()));
  }
  const TriangleMeshFile& f = ctx.triangle_mesh(file);
  std::vector<Vec3> vertices = f.vertices;
  if (const auto p = node.find("placement")) vertices = parse_and_apply_placement(*p, std::move(vertices));
  refuse_imprecise(vertices, file, ctx.pixel_mm());
  auto mesh = std::make_shared<SlicedMesh>(std::move(vertices), f.triangles);
  if (rule == InsideRule::kEvenOdd) {
    // The even-odd rule needs a closed mesh; orientation and intersections decide nothing by
    // it, but a mesh with flipped triangles or crossing parts is not the solid it claims to
    // be (overlapping parts would cancel), so they are refused too.
    MeshCheckParams params;
    params.intersection_tolerance = ctx.pixel_mm();
    params.stop = ctx.stop();
    const MeshCheck check = check_mesh(*mesh, params);
    if (!check.passed())
      file.fail(
          fmt::format("the mesh \"{}\" ({}, {} triangles) is {}. Give the shell \"inside_rule\": "
                      "\"winding-number\" to decide inside by the generalized winding number, which "
                      "tolerates gaps, flipped triangles and parts that overlap",
                      file.string(), f.format, f.triangles.size(), mesh_report(f, check, ctx.pixel_mm())));
  }
  auto shell = std::make_shared<TrimShell>();
  shell->name = fmt::format("\"{}\"", file.string());
  shell->mesh = std::move(mesh);
  shell->rule = rule;
  return shell;
}

}  // namespace trivox::detail
