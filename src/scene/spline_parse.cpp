// Geometry, spline fields and placements of a scene (docs/SCENE.md, "Geometry" and
// "Placement").
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/detail/sha256.h"

namespace trivox::detail {

const Model& SceneContext::model(const JsonView& file_field) {
  const std::string& name = file_field.string();
  const std::filesystem::path path = existing_file(file_field, "model file");
  const std::string key = path.string();
  if (const auto it = models_.find(key); it != models_.end()) return it->second;
  try {
    // Hashed before it is parsed: a file changed in between makes the job refuse to resume
    // rather than mix two versions.
    std::string digest = sha256_file(path, stop()).sha256;
    const Model& model = models_.emplace(key, read_model(path, stop())).first->second;
    model_sha256_[key] = digest;
    input_files_.push_back(SceneInputFile{name, std::move(digest)});
    return model;
  } catch (const CancelledError&) {
    throw;  // a stop is no fault of the file
  } catch (const UnsupportedError& e) {
    throw UnsupportedError(source_, 0, file_field.pointer(),
                           fmt::format("the model file \"{}\" uses an unsupported feature: {}", name, e.what()));
  } catch (const Error& e) {
    file_field.fail(fmt::format("cannot use the model file \"{}\": {}", name, e.what()));
  }
}

const std::string& SceneContext::model_sha256(const JsonView& file_field) {
  model(file_field);
  std::filesystem::path path(file_field.string());
  if (path.is_relative()) path = base_dir_ / path;
  return model_sha256_.at(path.lexically_normal().string());
}

TensorSpline parse_inline_spline(const JsonView& node, int param_dim, int point_dim) {
  node.expect_object({"orders", "knots", "points", "weights"});
  const auto pd = static_cast<std::size_t>(param_dim);
  const std::vector<JsonView> orders = node.at("orders").elements(pd, pd);
  const std::vector<JsonView> knot_nodes = node.at("knots").elements(pd, pd);
  std::vector<KnotVector> knots;
  std::size_t total = 1;
  for (std::size_t d = 0; d < pd; ++d) {
    const int order = orders[d].integer_in(1, kMaxOrder);
    try {
      knots.emplace_back(order, knot_nodes[d].numbers());
    } catch (const ModelError& e) {
      knot_nodes[d].fail(e.what());
    }
    total *= static_cast<std::size_t>(knots.back().num_ctrl());
  }
  const JsonView points_node = node.at("points");
  const std::vector<JsonView> points = points_node.elements();
  if (points.size() != total) {
    std::string counts;
    for (std::size_t d = 0; d < pd; ++d) counts += fmt::format("{}{}", d ? " x " : "", knots[d].num_ctrl());
    static const char* const kOrder[] = {"", "", "u fastest, then v", "u fastest, then v, then w"};
    points_node.fail(fmt::format("expected {} = {} control points ({}counts from the knots and orders), got {}", counts,
                                 total, pd > 1 ? std::string(kOrder[pd]) + "; " : "", points.size()));
  }
  const auto dim = static_cast<std::size_t>(point_dim);
  std::vector<double> coords;
  coords.reserve(total * dim);
  for (const JsonView& p : points) {
    if (point_dim == 1 && p.is_number()) {
      coords.push_back(p.number());
      continue;
    }
    const std::vector<double> c = p.numbers(dim, dim);
    coords.insert(coords.end(), c.begin(), c.end());
  }
  std::vector<double> weights;
  if (const auto w = node.find("weights")) {
    const std::vector<JsonView> ws = w->elements();
    if (ws.size() != total)
      w->fail(fmt::format("expected {} weights (one per control point), got {}", total, ws.size()));
    for (const JsonView& e : ws) {
      const double v = e.number();
      if (!(v > 0.0)) e.fail(fmt::format("weight {} is not > 0", v));
      weights.push_back(v);
    }
  }
  try {
    return TensorSpline(std::move(knots), point_dim, std::move(coords), std::move(weights));
  } catch (const ModelError& e) {
    node.fail(e.what());
  }
}

namespace {

// The trivariates of a model (param_dim 3), by position in the file.
std::vector<const Patch*> trivariates(const Model& model) {
  std::vector<const Patch*> out;
  for (int i : model.volume_indices()) out.push_back(&model.patches[static_cast<std::size_t>(i)]);
  return out;
}

std::string patch_description(const Patch& p) {
  return p.source_line > 0 ? fmt::format("\"{}\" (line {})", p.name, p.source_line) : fmt::format("\"{}\"", p.name);
}

// The patch a "patch" field selects among `vols` (the only one when the field is absent).
std::size_t select_patch(const JsonView& node, const std::vector<const Patch*>& vols, bool allow_all) {
  const std::string& file = node.at("file").string();
  if (vols.empty()) node.at("file").fail(fmt::format("the file \"{}\" holds no trivariate", file));
  const auto patch = node.find("patch");
  if (!patch) {
    if (vols.size() != 1)
      node.fail(
          fmt::format("the file \"{}\" holds {} trivariates; say which with \"patch\" (0 to "
                      "{}{})",
                      file, vols.size(), vols.size() - 1, allow_all ? ", or \"all\"" : ""));
    return 0;
  }
  return static_cast<std::size_t>(patch->integer_in(0, static_cast<int>(vols.size()) - 1));
}

Volume make_volume(const JsonView& where, const TensorSpline& spline, const std::string& what) {
  if (spline.point_dim() != 3)
    where.fail(
        fmt::format("{} has {} coordinate(s) per control point; geometry needs 3 (x, y, z "
                    "in mm)",
                    what, spline.point_dim()));
  try {
    return Volume(spline);
  } catch (const ModelError& e) {
    where.fail(fmt::format("{}: {}", what, e.what()));
  }
}

}  // namespace

std::vector<GeometryPart> parse_geometry(const JsonView& node, SceneContext& ctx) {
  if (!node.is_object()) node.fail(fmt::format("expected an object, got {}", JsonView::describe(node.json())));
  std::vector<GeometryPart> parts;
  if (is_constructed_geometry(node)) {
    parts.push_back({parse_constructed_geometry(node, ctx), ""});
    return parts;
  }
  if (is_bounding_box_geometry(node)) {
    parts.push_back({parse_bounding_box_geometry(node, ctx), ""});
    return parts;
  }
  if (!node.find("file")) {
    parts.push_back({make_volume(node, parse_inline_spline(node, 3, 3), "the inline volume"), ""});
    return parts;
  }
  node.expect_object({"file", "patch", "allow_fold"});
  if (const auto a = node.find("allow_fold")) a->boolean();
  const Model& model = ctx.model(node.at("file"));
  const std::vector<const Patch*> vols = trivariates(model);
  const auto patch = node.find("patch");
  if (patch && patch->is_string()) {
    if (patch->string() != "all")
      patch->fail(fmt::format("expected a patch index or \"all\", got \"{}\"", patch->string()));
    if (vols.empty())
      node.at("file").fail(fmt::format("the file \"{}\" holds no trivariate", node.at("file").string()));
    for (std::size_t i = 0; i < vols.size(); ++i)
      parts.push_back(
          {make_volume(*patch, vols[i]->spline, fmt::format("trivariate {} {}", i, patch_description(*vols[i]))),
           std::to_string(i)});
    return parts;
  }
  const std::size_t i = select_patch(node, vols, true);
  parts.push_back({make_volume(patch ? *patch : node, vols[i]->spline,
                               fmt::format("trivariate {} {}", i, patch_description(*vols[i]))),
                   ""});
  return parts;
}

std::filesystem::path SceneContext::existing_file(const JsonView& file_field, std::string_view what) const {
  const std::string& name = file_field.string();
  if (name.empty()) file_field.fail("the file name is empty");
  std::filesystem::path path(name);
  if (path.is_relative()) path = base_dir_ / path;
  path = path.lexically_normal();
  // One check of the file's kind (io/detail/regular_file.h): a device or a FIFO is named as
  // what it is, never read, nor called missing.
  const std::optional<std::string> problem = not_a_regular_file(path);
  if (problem == "no file")
    file_field.fail(
        fmt::format("cannot read the {} \"{}\": there is no file {} (names are relative to the "
                    "scene file's folder)",
                    what, name, path.string()));
  if (problem == "a directory")
    file_field.fail(fmt::format("cannot read the {} \"{}\": {} is a directory, not a file", what, name, path.string()));
  if (problem)
    file_field.fail(
        fmt::format("cannot read the {} \"{}\": {} is {}, not a regular file", what, name, path.string(), *problem));
  return path;
}

TensorSpline parse_field(const JsonView& node, SceneContext& ctx, int point_dim) {
  if (!node.is_object()) node.fail(fmt::format("expected an object, got {}", JsonView::describe(node.json())));
  if (!node.find("file")) {
    if (point_dim == kAnyPointDim) {
      const JsonView first = node.at("points").elements(1).front();
      point_dim = first.is_number() ? 1 : static_cast<int>(first.elements(1).size());
    }
    return parse_inline_spline(node, 3, point_dim);
  }
  node.expect_object({"file", "patch"});
  const Model& model = ctx.model(node.at("file"));
  const std::vector<const Patch*> vols = trivariates(model);
  const std::size_t i = select_patch(node, vols, false);
  const TensorSpline& spline = vols[i]->spline;
  if (point_dim != kAnyPointDim && spline.point_dim() != point_dim)
    node.fail(fmt::format("trivariate {} {} of \"{}\" has {} component(s); this field needs {}", i,
                          patch_description(*vols[i]), node.at("file").string(), spline.point_dim(), point_dim));
  return spline;
}

namespace {

struct Affine {
  Mat3 a{{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
  Vec3 t{};
};

Mat3 multiply(const Mat3& p, const Mat3& q) {
  Mat3 r;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t k = 0; k < 3; ++k) r.m[i][j] += p.m[i][k] * q.m[k][j];
  return r;
}

Mat3 rotation(int axis, double degrees) {
  const double r = degrees * std::numbers::pi / 180.0;
  const double c = std::cos(r), s = std::sin(r);
  Mat3 m{{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
  const auto a = static_cast<std::size_t>((axis + 1) % 3), b = static_cast<std::size_t>((axis + 2) % 3);
  m.m[a][a] = c;
  m.m[a][b] = -s;
  m.m[b][a] = s;
  m.m[b][b] = c;
  return m;
}

Affine parse_placement(const JsonView& node) {
  node.expect_object({"matrix", "translate", "rotate_deg", "scale"});
  Affine f;
  if (const auto matrix = node.find("matrix")) {
    if (node.json().size() > 1)
      node.fail(
          "\"matrix\" gives the whole placement; leave out \"translate\", \"rotate_deg\" "
          "and \"scale\" beside it");
    const std::vector<JsonView> rows = matrix->elements(4, 4);
    for (std::size_t i = 0; i < 4; ++i) {
      const std::vector<double> row = rows[i].numbers(4, 4);
      if (i == 3) {
        if (row[0] != 0 || row[1] != 0 || row[2] != 0 || row[3] != 1)
          rows[i].fail(
              "the last row must be [0, 0, 0, 1]: placements are affine (projective "
              "maps would not keep the volume a spline of the same kind)");
        break;
      }
      for (std::size_t j = 0; j < 3; ++j) f.a.m[i][j] = row[j];
      f.t[static_cast<int>(i)] = row[3];
    }
  } else {
    Mat3 s{{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
    if (const auto scale = node.find("scale")) {
      const std::vector<double> k = scale->is_number() ? std::vector<double>(3, scale->number()) : scale->numbers(3, 3);
      for (std::size_t d = 0; d < 3; ++d) s.m[d][d] = k[d];
    }
    Mat3 r{{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
    if (const auto rot = node.find("rotate_deg")) {
      const std::vector<double> deg = rot->numbers(3, 3);
      // About the fixed x axis first, then y, then z.
      for (int axis = 0; axis < 3; ++axis) r = multiply(rotation(axis, deg[static_cast<std::size_t>(axis)]), r);
    }
    f.a = multiply(r, s);
    if (const auto t = node.find("translate")) {
      const std::vector<double> v = t->numbers(3, 3);
      f.t = {v[0], v[1], v[2]};
    }
  }
  const double det = f.a.determinant();
  const double size = max_abs(f.a.column(0)) + max_abs(f.a.column(1)) + max_abs(f.a.column(2));
  // Said before the test of flatness, which an infinite determinant would fail as "singular".
  if (!std::isfinite(det))
    node.fail(
        fmt::format("the placement overflows: its determinant is {} (a scale or matrix entries beyond what a "
                    "double holds)",
                    det));
  if (!(std::abs(det) > 1e-12 * size * size * size))
    node.fail(
        fmt::format("the placement is singular (determinant {}): it would flatten the "
                    "volume",
                    det));
  return f;
}

}  // namespace

TensorSpline parse_and_apply_placement(const JsonView& node, const TensorSpline& spline) {
  const Affine f = parse_placement(node);
  // Affine maps commute with the (rational) B-spline combination of Euclidean control
  // points, so transforming the points transforms the volume or surface exactly (The NURBS
  // Book, 4.4).
  return spline.transformed([&f](std::span<double> p) {
    const Vec3 q = f.a * Vec3{p[0], p[1], p[2]} + f.t;
    p[0] = q.x;
    p[1] = q.y;
    p[2] = q.z;
  });
}

std::vector<Vec3> parse_and_apply_placement(const JsonView& node, std::vector<Vec3> points) {
  const Affine f = parse_placement(node);
  for (Vec3& p : points) p = f.a * p + f.t;
  return points;
}

Volume parse_and_apply_placement(const JsonView& node, const Volume& volume) {
  return Volume(parse_and_apply_placement(node, volume.spline()));
}

}  // namespace trivox::detail
