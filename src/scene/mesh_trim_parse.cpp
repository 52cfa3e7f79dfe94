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

bool is_bounding_box_geometry(const JsonView& node) { return node.is_object() && node.find("bounding_box"); }

Volume parse_bounding_box_geometry(const JsonView& node, SceneContext& ctx) {
  node.expect_object({"bounding_box"});
  const JsonView box = node.at("bounding_box");
  box.expect_object({"mesh", "placement", "margin_mm"});
  const JsonView file = box.at("mesh");
  const TriangleMeshFile& f = ctx.triangle_mesh(file);
  std::vector<Vec3> vertices = f.vertices;
  if (const auto p = box.find("placement")) vertices = parse_and_apply_placement(*p, std::move(vertices));
  refuse_imprecise(vertices, file, ctx.pixel_mm());
  double margin = 0;
  if (const auto m = box.find("margin_mm")) {
    margin = m->number();
    if (!(margin >= 0) || !std::isfinite(margin)) m->fail(fmt::format("expected a margin >= 0 mm, got {}", margin));
  }
  Box3 bounds;
  for (const Vec3& v : vertices) bounds.expand(v);
  const Vec3 lo = bounds.lo - Vec3{margin, margin, margin}, hi = bounds.hi + Vec3{margin, margin, margin};
  if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
    file.fail(
        fmt::format("the mesh \"{}\" is flat ({:.6g} x {:.6g} x {:.6g} mm where it is placed): a box around "
                    "it has no interior; give a \"margin_mm\"",
                    file.string(), hi.x - lo.x, hi.y - lo.y, hi.z - lo.z));
  if (!std::isfinite(hi.x - lo.x) || !std::isfinite(hi.y - lo.y) || !std::isfinite(hi.z - lo.z))
    box.at("margin_mm").fail("the box around the mesh overflows");
  // Corners u fastest, then v, then w: u, v and w run along x, y and z.
  std::vector<double> points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        points.push_back(i == 0 ? lo.x : hi.x);
        points.push_back(j == 0 ? lo.y : hi.y);
        points.push_back(k == 0 ? lo.z : hi.z);
      }
  const KnotVector knots(2, {0, 0, 1, 1});
  return Volume(TensorSpline({knots, knots, knots}, 3, std::move(points)));
}

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
                      file.string(), f.format, f.triangles.size(), mesh_check_report(f, check, ctx.pixel_mm())));
  }
  auto shell = std::make_shared<TrimShell>();
  shell->name = fmt::format("\"{}\"", file.string());
  shell->mesh = std::move(mesh);
  shell->rule = rule;
  return shell;
}

}  // namespace trivox::detail
