// Constructed geometry of a scene (docs/SCENE.md, "Constructed geometry"): a cell's volume
// built from curves and surfaces by one of the constructors of include/trivox/construct/.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "scene/construction_probe.h"
#include "scene/scene_parse.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/extrude.h"
#include "trivox/construct/join.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/shell.h"
#include "trivox/construct/sweep.h"
#include "trivox/construct/untangle.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox::detail {

namespace {

constexpr std::array<std::string_view, 6> kConstructors = {"extrude", "ruled", "revolve", "sweep", "coons", "shell"};

Vec3 vec3(const JsonView& node) {
  const std::vector<double> v = node.numbers(3, 3);
  return {v[0], v[1], v[2]};
}

Vec3 nonzero_vec3(const JsonView& node) {
  const Vec3 v = vec3(node);
  if (!(norm(v) > 0.0)) node.fail("the vector is zero");
  return v;
}

// The keys every constructor takes beside its own.
JacobianCheckParams check_params(const JsonView& node) {
  JacobianCheckParams p;
  p.samples_per_direction = 9;
  if (const auto s = node.find("jacobian_samples")) p.samples_per_direction = s->integer_in(2, 65);
  return p;
}

// The constructor's object and its keys: its own plus the common ones.
void expect_keys(const JsonView& node, std::initializer_list<std::string_view> own) {
  std::vector<std::string_view> keys(own);
  keys.push_back("jacobian_samples");
  keys.push_back("allow_fold");
  for (const auto& [key, value] : node.members())
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      std::string allowed;
      for (std::string_view k : keys) allowed += fmt::format("{}\"{}\"", allowed.empty() ? "" : ", ", k);
      value.fail(fmt::format("unknown key \"{}\"; the keys allowed here are {}", key, allowed));
    }
}

const char* const kSurface = "surface";

// {"knots_per_span": K, "iterations": N, "samples_per_span": S, "target": T}, all optional.
UntangleParams parse_untangle(const JsonView& node) {
  if (!node.is_object()) node.fail(fmt::format("expected an object, got {}", JsonView::describe(node.json())));
  constexpr std::array<std::string_view, 4> kKeys = {"knots_per_span", "iterations", "samples_per_span", "target"};
  for (const auto& [key, value] : node.members())
    if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end())
      value.fail(
          fmt::format("unknown key \"{}\"; the keys allowed here are \"knots_per_span\", \"iterations\", "
                      "\"samples_per_span\", \"target\"",
                      key));
  UntangleParams p;
  if (const auto v = node.find("knots_per_span")) p.knots_per_span = v->integer_in(0, 8);
  if (const auto v = node.find("iterations")) p.iterations = v->integer_in(0, 100000);
  if (const auto v = node.find("samples_per_span")) p.samples_per_span = v->integer_in(1, 16);
  if (const auto v = node.find("target")) {
    p.target_relative = v->number();
    if (!(p.target_relative > 0.0 && p.target_relative < 1.0)) v->fail("the target must be > 0 and < 1");
  }
  return p;
}

// The six faces of a closed shell in any order: an array of six surfaces, or {"file": F}, all
// the surfaces of a model file.
std::vector<TensorSpline> parse_shell_faces(const JsonView& node, SceneContext& ctx) {
  std::vector<TensorSpline> out;
  if (node.is_array()) {
    for (const JsonView& e : node.elements(6, 6)) out.push_back(parse_curve_or_surface(e, ctx, 2));
    return out;
  }
  if (!node.is_object())
    node.fail(
        fmt::format("expected an array of six surfaces or {{\"file\": ...}}, got {}", JsonView::describe(node.json())));
  node.expect_object({"file"});
  const JsonView file = node.at("file");
  for (const Patch& p : ctx.model(file).patches)
    if (p.spline.param_dim() == 2) out.push_back(p.spline);
  if (out.size() != 6)
    file.fail(
        fmt::format("the file \"{}\" holds {} surfaces; a shell of cube topology has 6", file.string(), out.size()));
  return out;
}

// A Coons constructor's six faces: "u0" to "w1", or "faces", a closed shell's six surfaces in
// any order, arranged as coons() expects.
std::array<TensorSpline, 6> coons_faces(const JsonView& c, SceneContext& ctx) {
  if (const auto all = c.find("faces")) {
    for (int i = 0; i < 6; ++i)
      if (c.find(coons_face_name(i)))
        c.at(coons_face_name(i)).fail("give the faces either as \"faces\" or as \"u0\" to \"w1\", not both");
    const std::vector<TensorSpline> shell = parse_shell_faces(*all, ctx);
    try {
      return arrange_cube_faces(shell);
    } catch (const ModelError& e) {
      c.fail(e.what());
    }
  }
  std::vector<TensorSpline> f;
  for (int i = 0; i < 6; ++i) f.push_back(parse_curve_or_surface(c.at(coons_face_name(i)), ctx, 2));
  return {f[0], f[1], f[2], f[3], f[4], f[5]};
}

// Appends "file NAME SHA-256" for every model file `node` names, in document order.
void add_model_files(const JsonView& node, SceneContext& ctx, std::string& text) {
  if (node.is_object()) {
    for (const auto& [key, value] : node.members()) {
      if (key == "file" && value.is_string())
        text += fmt::format("file {} {}\n", value.string(), ctx.model_sha256(value));
      else
        add_model_files(value, ctx, text);
    }
  } else if (node.is_array()) {
    for (const JsonView& e : node.elements()) add_model_files(e, ctx, text);
  }
}

// The construction cache's key (construction_cache.h): the program, the constructor and its
// object as read (canonical: keys sorted, no whitespace, numbers written to round-trip), and
// the SHA-256 of every model file it names.
std::string cache_key(std::string_view kind, const JsonView& c, SceneContext& ctx, const std::string& program) {
  std::string text = fmt::format("trivox construction cache key 1\n{}\nconstructor {}\n{}\n", program, kind,
                                 nlohmann::json::parse(c.json().dump()).dump());
  add_model_files(c, ctx, text);
  return sha256_hex(text);
}

// Builds the constructor's volume, its inputs already read from `node`, or takes it from the
// scene's construction cache when that holds it and it agrees with its inputs at the points
// `probe` checks (construction_probe.h; else the entry is built again with a warning), and
// stores it there once built.
template <class Build, class Probe>
Constructed run(std::string_view kind, const JsonView& node, SceneContext& ctx, Build build, Probe probe) {
  ConstructionCache* cache = ctx.construction_cache();
  std::string key;
  if (cache != nullptr && !cache->program_identity().empty()) {
    key = cache_key(kind, node, ctx, cache->program_identity());
    if (std::optional<Constructed> hit = cache->load(key, ctx.stop())) {
      const std::optional<std::string> problem = probe(*hit);
      if (!problem) return std::move(*hit);
      cache->reject(key, *problem);
    }
  }
  Constructed built = [&] {
    try {
      return build();
    } catch (const ModelError& e) {
      node.fail(e.what());
    }
  }();
  if (!key.empty()) cache->store(key, built);
  return built;
}

Constructed build(std::string_view kind, const JsonView& c, SceneContext& ctx) {
  const JacobianCheckParams check = check_params(c);
  if (kind == "extrude") {
    expect_keys(c, {kSurface, "vector_mm"});
    const TensorSpline s = parse_curve_or_surface(c.at(kSurface), ctx, 2);
    ExtrudeParams p;
    p.vector_mm = nonzero_vec3(c.at("vector_mm"));
    p.check = check;
    const std::array<FaceProbe, 2> faces{FaceProbe{&s, 2, false, {0, 1}, {}},
                                         FaceProbe{&s, 2, true, {0, 1}, p.vector_mm}};
    return run(
        kind, c, ctx, [&] { return extrude(s, p); },
        [&](const Constructed& hit) { return probe_faces(hit.volume, faces); });
  }
  if (kind == "ruled") {
    expect_keys(c, {"from", "to"});
    const TensorSpline a = parse_curve_or_surface(c.at("from"), ctx, 2);
    const TensorSpline b = parse_curve_or_surface(c.at("to"), ctx, 2);
    const std::array<FaceProbe, 2> faces{FaceProbe{&a, 2, false, {0, 1}, {}}, FaceProbe{&b, 2, true, {0, 1}, {}}};
    return run(
        kind, c, ctx, [&] { return ruled(a, b, RuledParams{check}); },
        [&](const Constructed& hit) { return probe_faces(hit.volume, faces); });
  }
  if (kind == "revolve") {
    expect_keys(c, {"profile", "axis_point_mm", "axis_dir", "angle_deg", "angle_param"});
    const TensorSpline s = parse_curve_or_surface(c.at("profile"), ctx, 2);
    RevolveParams p;
    if (const auto v = c.find("axis_point_mm")) p.axis_point_mm = vec3(*v);
    if (const auto v = c.find("axis_dir")) p.axis_dir = nonzero_vec3(*v);
    if (const auto v = c.find("angle_deg")) {
      p.angle_deg = v->number();
      if (!(p.angle_deg > 0.0 && p.angle_deg <= 360.0))
        v->fail(fmt::format("the angle {} is not in (0, 360]", p.angle_deg));
    }
    if (const auto v = c.find("angle_param")) {
      const std::string& name = v->string();
      if (name != "u" && name != "v" && name != "w")
        v->fail(fmt::format("expected \"u\", \"v\" or \"w\", got \"{}\"", name));
      p.angle_direction = name[0] - 'u';
    }
    p.check = check;
    return run(
        kind, c, ctx, [&] { return revolve(s, p); },
        [&](const Constructed& hit) { return probe_revolve(hit.volume, s, p); });
  }
  if (kind == "sweep") {
    expect_keys(c, {"section", "path", "twist_deg", "stations", "initial_x"});
    const TensorSpline section = parse_curve_or_surface(c.at("section"), ctx, 2);
    const TensorSpline path = parse_curve_or_surface(c.at("path"), ctx, 1);
    SweepParams p;
    if (const auto v = c.find("twist_deg")) p.twist_deg = v->number();
    if (const auto v = c.find("stations")) p.stations = v->integer_in(4, 4096);
    if (const auto v = c.find("initial_x")) p.initial_x = nonzero_vec3(*v);
    p.check = check;
    return run(
        kind, c, ctx, [&] { return sweep(section, path, p); },
        [&](const Constructed& hit) { return probe_sweep(hit, section, path); });
  }
  if (kind == "coons") {
    expect_keys(c, {"u0", "u1", "v0", "v1", "w0", "w1", "faces", "untangle"});
    CoonsParams p;
    p.check = check;
    std::optional<UntangleParams> untangling;
    if (const auto u = c.find("untangle")) {
      untangling = parse_untangle(*u);
      untangling->stop = ctx.stop();
    }
    // The Coons volume, untangled when asked: only its interior control points move.
    auto make = [&](const std::array<TensorSpline, 6>& faces) {
      Constructed built = coons(faces, p);
      if (!untangling) return built;
      UntangleResult r = untangle(built.volume.spline(), *untangling);
      Volume volume(std::move(r.spline));
      ConstructionReport report = inspect_volume(volume, check);
      report.constructor = "coons";
      return Constructed{std::move(volume), std::move(report)};
    };
    const std::array<TensorSpline, 6> faces = coons_faces(c, ctx);
    return run(
        kind, c, ctx, [&] { return make(faces); },
        [&](const Constructed& hit) { return probe_coons(hit.volume, faces); });
  }
  expect_keys(c, {kSurface, "thickness_mm", "side", "knots_per_span"});
  const TensorSpline s = parse_curve_or_surface(c.at(kSurface), ctx, 2);
  ShellParams p;
  const JsonView t = c.at("thickness_mm");
  p.thickness_mm = t.number();
  if (!(p.thickness_mm > 0.0)) t.fail(fmt::format("{} is not > 0", p.thickness_mm));
  if (const auto v = c.find("side")) {
    const std::string& side = v->string();
    const std::optional<ShellSide> named = shell_side_from_name(side);
    if (!named) v->fail(fmt::format("expected \"outside\", \"inside\" or \"centred\", got \"{}\"", side));
    p.side = *named;
  }
  if (const auto v = c.find("knots_per_span")) p.knots_per_span = v->integer_in(0, 8);
  p.check = check;
  return run(
      kind, c, ctx, [&] { return thick_shell(s, p); }, [&](const Constructed& hit) { return probe_shell(hit, s, p); });
}

// "patches": rows of surface indices of one file, joined into one surface (construct/join.h).
TensorSpline parse_patch_grid(const JsonView& grid, const JsonView& file, const std::vector<const Patch*>& surfaces) {
  std::vector<std::vector<TensorSpline>> rows;
  std::size_t cols = 0;
  for (const JsonView& row : grid.elements(1, 4096)) {
    const std::vector<JsonView> entries = row.elements(1, 4096);
    if (!rows.empty() && entries.size() != cols)
      row.fail(fmt::format("this row names {} patches, the first row {}; the grid must be rectangular", entries.size(),
                           cols));
    cols = entries.size();
    rows.emplace_back();
    for (const JsonView& e : entries) {
      const std::size_t i = static_cast<std::size_t>(e.integer_in(0, static_cast<int>(surfaces.size()) - 1));
      const TensorSpline& s = surfaces[i]->spline;
      if (s.point_dim() != 3)
        e.fail(fmt::format("surface {} of \"{}\" has {} coordinate(s) per control point; geometry needs 3", i,
                           file.string(), s.point_dim()));
      rows.back().push_back(s);
    }
  }
  try {
    return join_surfaces(rows);
  } catch (const ModelError& e) {
    grid.fail(e.what());
  }
}

}  // namespace

TensorSpline parse_curve_or_surface(const JsonView& node, SceneContext& ctx, int param_dim) {
  const char* what = param_dim == 1 ? "curve" : "surface";
  if (!node.is_object())
    node.fail(fmt::format("expected a {} (an object), got {}", what, JsonView::describe(node.json())));
  if (!node.find("file")) {
    const TensorSpline s = parse_inline_spline(node, param_dim, 3);
    return s;
  }
  node.expect_object({"file", "patch", "patches"});
  const JsonView file = node.at("file");
  const Model& model = ctx.model(file);
  std::vector<const Patch*> found;
  for (const Patch& p : model.patches)
    if (p.spline.param_dim() == param_dim) found.push_back(&p);
  if (found.empty()) file.fail(fmt::format("the file \"{}\" holds no {}", file.string(), what));
  if (const auto grid = node.find("patches")) {
    if (param_dim != 2) grid->fail("only surfaces are joined from a grid of patches");
    if (node.find("patch")) grid->fail("give either \"patch\" or \"patches\", not both");
    return parse_patch_grid(*grid, file, found);
  }
  std::size_t i = 0;
  if (const auto patch = node.find("patch")) {
    i = static_cast<std::size_t>(patch->integer_in(0, static_cast<int>(found.size()) - 1));
  } else if (found.size() > 1) {
    node.fail(fmt::format("the file \"{}\" holds {} {}s; say which with \"patch\" (0 to {})", file.string(),
                          found.size(), what, found.size() - 1));
  }
  const TensorSpline& s = found[i]->spline;
  if (s.point_dim() != 3)
    node.fail(fmt::format("{} {} of \"{}\" has {} coordinate(s) per control point; geometry needs 3", what, i,
                          file.string(), s.point_dim()));
  return s;
}

bool is_constructed_geometry(const JsonView& node) {
  for (std::string_view k : kConstructors)
    if (node.find(k)) return true;
  return false;
}

JacobianReport checked_jacobian(const Volume& volume, const std::string& what, const JsonView& geometry,
                                double pixel_mm) {
  JacobianReport jacobian;
  try {
    jacobian = check_jacobian(volume);
  } catch (const ModelError& e) {
    geometry.fail(fmt::format("{}: {}", what, e.what()));
  }
  if (jacobian.zero != jacobian.positive + jacobian.negative + jacobian.zero) return jacobian;
  const Box3 box = volume.bounds();
  const double far = std::max({std::abs(box.lo.x), std::abs(box.lo.y), std::abs(box.lo.z), std::abs(box.hi.x),
                               std::abs(box.hi.y), std::abs(box.hi.z)});
  if (!(far * std::numeric_limits<double>::epsilon() <= 1e-3 * pixel_mm)) return jacobian;
  geometry.fail(
      fmt::format("{} has no interior: det J vanishes at all {} samples (a direction of order 1, or "
                  "control points all on one plane, line or point), so it holds no voxel",
                  what, jacobian.zero));
  return jacobian;
}

bool geometry_allows_fold(const JsonView& geometry) {
  if (!geometry.is_object()) return false;
  if (geometry.find("file")) {
    const auto allow = geometry.find("allow_fold");
    return allow && allow->boolean();
  }
  if (!is_constructed_geometry(geometry) || geometry.json().size() != 1) return false;
  const auto allow = geometry.members().front().second.find("allow_fold");
  return allow && allow->boolean();
}

Constructed parse_construction(const JsonView& node, SceneContext& ctx) {
  if (!node.is_object()) node.fail(fmt::format("expected an object, got {}", JsonView::describe(node.json())));
  if (node.json().size() != 1 || !is_constructed_geometry(node)) {
    std::string keys;
    for (const auto& [key, value] : node.members()) keys += fmt::format("{}\"{}\"", keys.empty() ? "" : ", ", key);
    node.fail(
        fmt::format("a constructed geometry is an object with exactly one key, the constructor (\"extrude\", "
                    "\"ruled\", \"revolve\", \"sweep\", \"coons\" or \"shell\"); got {}",
                    keys));
  }
  const auto [kind, c] = node.members().front();
  if (!c.is_object()) c.fail(fmt::format("expected an object, got {}", JsonView::describe(c.json())));
  if (const auto a = c.find("allow_fold")) a->boolean();
  return build(kind, c, ctx);
}

Volume parse_constructed_geometry(const JsonView& node, SceneContext& ctx) {
  Constructed built = parse_construction(node, ctx);
  const auto [kind, c] = node.members().front();
  const auto allow = c.find("allow_fold");
  if (built.report.folds() && !(allow && allow->boolean()))
    c.fail(
        fmt::format("the constructed volume folds over itself ({}); fix the input or set \"allow_fold\": true to "
                    "slice it anyway (each voxel then takes one of its preimages)",
                    built.report.describe()));
  return std::move(built.volume);
}

}  // namespace trivox::detail
