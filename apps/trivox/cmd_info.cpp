// `trivox info MODEL [--json]`: what a model file holds, patch by patch: kind, orders,
// control points, rational or not, parametric domain, the box of the control points (which
// contains the patch) and, for trivariates with 3D points, a sampled Jacobian check. For a
// triangle mesh file: its counts, its box and the checks of a mesh trim.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "stop_signal.h"
#include "trivox/io/model.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/scene/mesh_file_report.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/volume.h"

namespace trivox::cli {
namespace {

struct InfoOptions {
  std::string model_path;
  bool json = false;
  JacobianCheckParams jacobian;
  std::string printer = "j750-hm";  // a mesh's intersections are judged at its finest pitch
};

constexpr std::array<const char*, 3> kParamNames = {"u", "v", "w"};
constexpr std::array<const char*, 3> kCoordNames = {"x", "y", "z"};

const char* kind_name(int param_dim) {
  switch (param_dim) {
    case 1: return "curve";
    case 2: return "surface";
    default: return "trivariate";
  }
}

std::string count_of(std::size_t n, std::string_view one, std::string_view many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

// The Jacobian check applies to geometry trivariates only; a trivariate with other than 3
// coordinates per point is a field (material, scalar), not a map into model space.
std::optional<JacobianReport> jacobian_of(const TensorSpline& s, const JacobianCheckParams& p) {
  if (s.param_dim() != 3 || s.point_dim() != 3) return std::nullopt;
  return check_jacobian(Volume(s), p);
}

// The box of the control points in the first min(point_dim, 3) coordinates.
int box_dims(const TensorSpline& s) { return std::min(s.point_dim(), 3); }

nlohmann::ordered_json patch_json(int index, const Patch& patch, const JacobianCheckParams& params) {
  const TensorSpline& s = patch.spline;
  using Json = nlohmann::ordered_json;
  Json orders = Json::array(), ctrl = Json::array(), periodic = Json::array(), domain = Json::array(),
       knots = Json::array();
  for (int d = 0; d < s.param_dim(); ++d) {
    const KnotVector& kv = s.knots(d);
    orders.push_back(kv.order());
    ctrl.push_back(kv.num_ctrl());
    periodic.push_back(kv.is_periodic());
    domain.push_back({kv.lo(), kv.hi()});
    knots.push_back(std::vector<double>(kv.knots().begin(), kv.knots().end()));
  }
  const Box3 box = s.control_box();
  Json lo = Json::array(), hi = Json::array();
  for (int c = 0; c < box_dims(s); ++c) {
    lo.push_back(box.lo[c]);
    hi.push_back(box.hi[c]);
  }
  Json jacobian = nullptr;
  if (const auto report = jacobian_of(s, params)) {
    jacobian = {{"class", std::string(to_string(report->classification))},
                {"samples", report->positive + report->negative + report->zero},
                {"positive", report->positive},
                {"negative", report->negative},
                {"zero", report->zero},
                {"min_det", report->min_det},
                {"max_det", report->max_det}};
    if (report->classification == JacobianClass::kFolded) {
      Json folds = Json::array();
      for (const FoldRegion& f : fold_regions(Volume(s), params))
        folds.push_back({{"u", {f.box.lo.x, f.box.hi.x}},
                         {"v", {f.box.lo.y, f.box.hi.y}},
                         {"w", {f.box.lo.z, f.box.hi.z}},
                         {"samples", f.samples}});
      jacobian["folds"] = folds;
    }
  }
  return {{"index", index},
          {"name", patch.name},
          {"id", patch.id},
          {"line", patch.source_line},
          {"kind", kind_name(s.param_dim())},
          {"param_dim", s.param_dim()},
          {"point_dim", s.point_dim()},
          {"rational", s.is_rational()},
          {"orders", orders},
          {"control_points", ctrl},
          {"total_control_points", s.total_ctrl()},
          {"periodic", periodic},
          {"domain", domain},
          {"knots", knots},
          {"bounds", {{"lo", lo}, {"hi", hi}}},
          {"jacobian", jacobian}};
}

// "u [0, 3]" with 6 significant digits, as every number of the text output.
std::string range_text(const char* name, double lo, double hi) {
  return fmt::format("{} [{:.6g}, {:.6g}]", name, lo, hi);
}

void print_patch_text(int index, const Patch& patch, const JacobianCheckParams& params) {
  const TensorSpline& s = patch.spline;
  const auto n = static_cast<std::size_t>(s.param_dim());
  fmt::print("\npatch {} \"{}\" (id {}, line {})\n", index, patch.name, patch.id, patch.source_line);

  std::vector<std::string> periodic, orders, ctrl, domain;
  for (std::size_t d = 0; d < n; ++d) {
    const KnotVector& kv = s.knots(static_cast<int>(d));
    if (kv.is_periodic()) periodic.emplace_back(kParamNames[d]);
    orders.push_back(std::to_string(kv.order()));
    ctrl.push_back(std::to_string(kv.num_ctrl()));
    domain.push_back(range_text(kParamNames[d], kv.lo(), kv.hi()));
  }
  fmt::print("  {}, {}, point dimension {}{}\n", kind_name(s.param_dim()),
             s.is_rational() ? "rational (NURBS)" : "polynomial (B-spline)", s.point_dim(),
             periodic.empty() ? "" : fmt::format(", periodic in {}", fmt::join(periodic, " ")));
  fmt::print("  orders {}, control points {}{}\n", fmt::join(orders, " x "), fmt::join(ctrl, " x "),
             n > 1 ? fmt::format(" = {}", s.total_ctrl()) : "");
  fmt::print("  domain {}\n", fmt::join(domain, "  "));

  const Box3 box = s.control_box();
  if (s.point_dim() == 1) {  // a scalar field: the range of its values
    fmt::print("  control-point values [{:.6g}, {:.6g}]\n", box.lo.x, box.hi.x);
  } else {
    std::vector<std::string> bounds;
    for (int c = 0; c < box_dims(s); ++c)
      bounds.push_back(range_text(kCoordNames[static_cast<std::size_t>(c)], box.lo[c], box.hi[c]));
    fmt::print("  control-point box {}{}\n", fmt::join(bounds, "  "),
               s.point_dim() > 3 ? fmt::format(" (first 3 of {} coordinates)", s.point_dim()) : "");
  }

  if (const auto r = jacobian_of(s, params)) {
    fmt::print("  jacobian {} ({} samples: {} positive, {} negative, {} zero; det J in [{:.6g}, {:.6g}])\n",
               to_string(r->classification), r->positive + r->negative + r->zero, r->positive, r->negative, r->zero,
               r->min_det, r->max_det);
    if (r->classification == JacobianClass::kFolded) {
      const bool negative = r->positive >= r->negative;
      for (const FoldRegion& f : fold_regions(Volume(s), params))
        fmt::print("  folds: det J {} 0 at {} sample{} in {}  {}  {}\n", negative ? "<" : ">", f.samples,
                   f.samples == 1 ? "" : "s", range_text("u", f.box.lo.x, f.box.hi.x),
                   range_text("v", f.box.lo.y, f.box.hi.y), range_text("w", f.box.lo.z, f.box.hi.z));
    }
  } else if (n == 3) {
    fmt::print("  jacobian not checked: point dimension {} (a field, not a map into 3D)\n", s.point_dim());
  }
}

void print_text(const Model& model, const JacobianCheckParams& params) {
  std::vector<std::string> kinds;  // "1 trivariate", "2 surfaces", ...
  for (int dim = 3; dim >= 1; --dim) {
    const auto has_dim = [dim](const Patch& p) { return p.spline.param_dim() == dim; };
    const auto n = static_cast<std::size_t>(std::count_if(model.patches.begin(), model.patches.end(), has_dim));
    if (n > 0) kinds.push_back(count_of(n, kind_name(dim), fmt::format("{}s", kind_name(dim))));
  }
  fmt::print("{}: {}{}\n", model.source, count_of(model.patches.size(), "patch", "patches"),
             kinds.empty() ? "" : fmt::format(" ({})", fmt::join(kinds, ", ")));
  for (const ModelNote& note : model.notes) fmt::print("note: line {}: {}\n", note.line, note.text);
  for (std::size_t i = 0; i < model.patches.size(); ++i)
    print_patch_text(static_cast<int>(i), model.patches[i], params);
}

// A mesh file: what a mesh trim of it would be checked for, judged at the printer's finest
// pitch as a scene with that printer judges it.
void print_mesh_info(const InfoOptions& options) {
  const PrinterProfile printer = builtin_printer_profile(options.printer);
  const MeshFileReport r = describe_mesh_file(options.model_path, printer.finest_pitch_mm(), stop_on_signals());
  const Vec3 size = r.bounds.size();
  if (options.json) {
    const nlohmann::ordered_json doc = {{"source", r.source},
                                        {"format", r.format},
                                        {"triangles", r.triangles},
                                        {"vertices", r.vertices},
                                        {"dropped_degenerate", r.dropped_degenerate},
                                        {"ignored_primitives", r.ignored_primitives},
                                        {"bounds",
                                         {{"lo_mm", {r.bounds.lo.x, r.bounds.lo.y, r.bounds.lo.z}},
                                          {"hi_mm", {r.bounds.hi.x, r.bounds.hi.y, r.bounds.hi.z}},
                                          {"size_mm", {size.x, size.y, size.z}}}},
                                        {"checks",
                                         {{"printer", printer.name},
                                          {"intersection_tolerance_mm", r.intersection_tolerance_mm},
                                          {"closed", r.closed()},
                                          {"open_edges", r.open_edges},
                                          {"nonmanifold_edges", r.nonmanifold_edges},
                                          {"misoriented_edges", r.misoriented_edges},
                                          {"duplicate_triangles", r.duplicate_triangles},
                                          {"self_intersections", r.self_intersections},
                                          {"intersections_cut_short", r.intersections_cut_short},
                                          {"passed", r.passed},
                                          {"problems", r.problems}}}};
    fmt::print("{}\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
    return;
  }
  fmt::print("{}: {}, {} triangles, {} vertices\n", r.source, r.format, r.triangles, r.vertices);
  if (r.dropped_degenerate > 0 || r.ignored_primitives > 0)
    fmt::print("note: {} triangles that repeat a vertex dropped, {} points and lines ignored\n", r.dropped_degenerate,
               r.ignored_primitives);
  fmt::print("bounds: {}, {}, {} mm; size {:.6g} x {:.6g} x {:.6g} mm\n", range_text("x", r.bounds.lo.x, r.bounds.hi.x),
             range_text("y", r.bounds.lo.y, r.bounds.hi.y), range_text("z", r.bounds.lo.z, r.bounds.hi.z), size.x,
             size.y, size.z);
  const auto count = [](std::size_t n) { return n == 0 ? std::string("none") : std::to_string(n); };
  fmt::print("closed: {} (open edges: {}, non-manifold edges: {})\n", r.closed() ? "yes" : "no", count(r.open_edges),
             count(r.nonmanifold_edges));
  fmt::print("consistently oriented: {} (edges run the same way by both triangles: {})\n",
             r.misoriented_edges == 0 ? "yes" : "no", count(r.misoriented_edges));
  fmt::print("duplicate triangles: {}\n", count(r.duplicate_triangles));
  fmt::print("self-intersections: {}{} (longer than {:.4g} mm, the finest pitch of printer {})\n",
             r.intersections_cut_short ? "at least " : "", count(r.self_intersections), r.intersection_tolerance_mm,
             printer.name);
  if (r.passed)
    fmt::print("passes: a shell {{\"mesh\": ...}} trims by it with the even-odd rule (the default)\n");
  else
    fmt::print(
        "fails: {}. As a shell it trims only with \"inside_rule\": \"winding-number\" (docs/SCENE.md, \"Mesh "
        "trims\")\n",
        r.problems);
}

void run_info(const InfoOptions& options) {
  // A scene (JSON) gets the scene summary and the job estimate; models get their patches.
  std::string ext = std::filesystem::path(options.model_path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".json") {
    print_scene_info(options.model_path);
    return;
  }
  if (is_triangle_mesh_extension(ext)) {
    print_mesh_info(options);
    return;
  }
  const Model model = read_model(options.model_path, stop_on_signals());
  if (options.json) {
    // One patch per line: compact enough for models of many patches, still one JSON document.
    const auto dump = [](const nlohmann::ordered_json& j) {
      return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    };
    nlohmann::ordered_json notes = nlohmann::ordered_json::array();
    for (const ModelNote& note : model.notes) notes.push_back({{"line", note.line}, {"text", note.text}});
    fmt::print("{{\"source\":{},\"notes\":{},\"patches\":[\n", dump(model.source), dump(notes));
    for (std::size_t i = 0; i < model.patches.size(); ++i)
      fmt::print("  {}{}\n", dump(patch_json(static_cast<int>(i), model.patches[i], options.jacobian)),
                 i + 1 < model.patches.size() ? "," : "");
    fmt::print("]}}\n");
  } else {
    print_text(model, options.jacobian);
  }
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd =
      app.add_subcommand("info",
                         "Describe a model (patches, orders, control points, domain, bounds, Jacobian check), a "
                         "triangle mesh (its box and the checks of a mesh trim) or a scene (the job's estimate).");
  cmd->add_option("model", options->model_path,
                  "Model file: IRIT .itd, G+Smo .xml or GoTools .g2; a triangle mesh (.stl, .obj, .ply, .3mf) for "
                  "its box and the checks of a mesh trim; or a scene (.json) for a job estimate")
      ->required();
  cmd->add_option("--printer", options->printer,
                  fmt::format("For a mesh: the printer whose finest pitch self-intersections are judged at ({})",
                              fmt::join(builtin_printer_profile_names(), ", ")))
      ->check(CLI::IsMember(builtin_printer_profile_names()))
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "Print one JSON document instead of text");
  cmd->add_option("--jacobian-samples", options->jacobian.samples_per_direction,
                  "Grid points per direction (domain ends included) for the Jacobian check")
      ->check(CLI::Range(2, 101))
      ->capture_default_str();
  cmd->callback([options] { run_info(*options); });
}

}  // namespace trivox::cli
