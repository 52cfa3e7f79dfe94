// Named volumes and trims of a scene (docs/SCENE.md, "Volumes" and "Trimmed cells"): the
// clauses of a cell's "trim" and the closed shells they name.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <limits>

#include <fmt/format.h>

#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox::detail {

std::vector<SceneVolume> parse_volumes(const JsonView& node, SceneContext& ctx) {
  std::vector<SceneVolume> out;
  for (const JsonView& e : node.elements(1)) {
    e.expect_object({"name", "geometry", "placement"});
    const JsonView name = e.at("name");
    if (name.string().empty()) name.fail("a volume name must not be empty");
    for (const SceneVolume& other : out)
      if (other.name == name.string())
        name.fail(fmt::format("the volume name \"{}\" is taken by {} already", name.string(), other.pointer));
    std::vector<GeometryPart> parts = parse_geometry(e.at("geometry"), ctx);
    if (parts.size() != 1)
      e.at("geometry")
          .fail(fmt::format("a named volume is one trivariate; this geometry gives {} (name one "
                            "\"patch\")",
                            parts.size()));
    Volume v = std::move(parts.front().volume);
    if (const auto p = e.find("placement")) v = parse_and_apply_placement(*p, v);
    const JacobianReport jacobian =
        checked_jacobian(v, fmt::format("volume '{}'", name.string()), e.at("geometry"), ctx.pixel_mm());
    const bool folds = jacobian.classification == JacobianClass::kFolded;
    if (folds && !geometry_allows_fold(e.at("geometry")))
      e.at("geometry")
          .fail(fmt::format("volume '{}' folds over itself: det J takes both signs, so some points have several "
                            "(u,v,w); set \"allow_fold\": true in its geometry to accept it (a point is then "
                            "inside when any of them is)",
                            name.string()));
    out.push_back(SceneVolume{name.string(), e.pointer(), std::move(v), folds});
  }
  return out;
}

int volume_ref(const JsonView& name, const std::vector<SceneVolume>& volumes) {
  const std::string& n = name.string();
  for (std::size_t i = 0; i < volumes.size(); ++i)
    if (volumes[i].name == n) return static_cast<int>(i);
  std::string list;
  for (const SceneVolume& v : volumes) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", v.name);
  name.fail(volumes.empty() ? fmt::format("there is no volume \"{}\": the scene declares no \"volumes\"", n)
                            : fmt::format("there is no volume \"{}\" in \"volumes\"; the names are {}", n, list));
}

namespace {

// {"file": F} (every surface of a model file) or {"surfaces": [...]} (each inline or
// {"file", "patch"}), with an optional "placement"; the shell must be closed.
std::shared_ptr<const TrimShell> parse_shell(const JsonView& node, SceneContext& ctx, std::string_view what) {
  if (node.is_object() && node.find("mesh")) return parse_mesh_shell(node, ctx, what);
  if (!node.is_object())
    node.fail(fmt::format("expected {{\"file\": ...}}, {{\"surfaces\": [...]}} or {{\"mesh\": ...}}, got {}",
                          JsonView::describe(node.json())));
  node.expect_object({"file", "surfaces", "placement"});
  auto shell = std::make_shared<TrimShell>();
  const auto file = node.find("file");
  const auto list = node.find("surfaces");
  if (file.has_value() == list.has_value())
    node.fail("give the shell's surfaces either as \"file\" or as \"surfaces\"");
  if (file) {
    shell->name = fmt::format("\"{}\"", file->string());
    std::string ext = std::filesystem::path(file->string()).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (is_triangle_mesh_extension(ext))
      file->fail(
          fmt::format("\"{}\" is a triangle mesh: give it as {{\"mesh\": \"{}\"}}", file->string(), file->string()));
    const Model& model = ctx.model(*file);
    if (!model.trimmed_models.empty()) {
      // A trimmed-surface model (IRIT MODEL): its trimmed surfaces, each restricted to its
      // loops; the other surfaces of the file are not part of the shell.
      int segment_base = 0;
      for (const TrimmedModel& m : model.trimmed_models) {
        for (std::size_t i = 0; i < m.surfaces.size(); ++i) {
          const TrimmedModel::Surface& srf = m.surfaces[i];
          TrimmedSurface t{fmt::format("MODEL '{}' (line {}), trimmed surface {} (line {})", m.name, m.source_line,
                                       i + 1, srf.source_line),
                           model.patches[static_cast<std::size_t>(srf.patch)].spline,
                           {}};
          for (const auto& loop : srf.loops) {
            std::vector<TrimmedSurface::Piece> pieces;
            for (int ref : loop) {
              const auto g = static_cast<std::size_t>(std::abs(ref) - 1);
              const TrimmedModel::Segment& seg = m.segments[g];
              const auto side = static_cast<std::size_t>(
                  std::find(seg.surfaces.begin(), seg.surfaces.end(), static_cast<int>(i)) - seg.surfaces.begin());
              if (side == seg.surfaces.size())
                file->fail(
                    fmt::format("{}: a loop uses segment {} (line {}), which has no curve in this surface's "
                                "(u, v)",
                                t.name, g + 1, seg.source_line));
              pieces.push_back({seg.curves[side], ref < 0, segment_base + static_cast<int>(g)});
            }
            t.loops.push_back(std::move(pieces));
          }
          shell->trimmed.push_back(std::move(t));
        }
        segment_base += static_cast<int>(m.segments.size());
      }
    } else {
      for (const Patch& p : model.patches)
        if (p.spline.param_dim() == 2) shell->surfaces.push_back(p.spline);
    }
    if (shell->surfaces.empty() && shell->trimmed.empty())
      file->fail(fmt::format("the file \"{}\" holds no surface", file->string()));
  } else {
    shell->name = fmt::format("the surfaces at {}", list->pointer());
    for (const JsonView& e : list->elements(1)) shell->surfaces.push_back(parse_curve_or_surface(e, ctx, 2));
  }
  if (const auto p = node.find("placement")) {
    for (TensorSpline& s : shell->surfaces) s = parse_and_apply_placement(*p, s);
    for (TrimmedSurface& t : shell->trimmed) t.surface = parse_and_apply_placement(*p, t.surface);
  }
  // Closed or not is a matter of topology, so the coarsest sampling tells.
  try {
    const ShellMesh mesh(*shell, std::numeric_limits<double>::infinity());
    if (mesh.open_edges() > 0)
      (file ? *file : node)
          .fail(fmt::format("the {} shell {} is not closed: {} edges of its tessellation border only one "
                            "surface (a gap between surfaces, or a surface missing), so inside and outside "
                            "are undefined",
                            what, shell->name, mesh.open_edges()));
  } catch (const ModelError& e) {
    node.fail(e.what());
  }
  return shell;
}

}  // namespace

Trim parse_trim(const JsonView& node, SceneContext& ctx, const std::vector<SceneVolume>& volumes, int own_volume) {
  Trim trim;
  for (const JsonView& e : node.elements(1)) {
    e.expect_object({"side", "volume", "shell", "parametric"});
    TrimClause clause;
    if (const auto side = e.find("side")) {
      const std::string& s = side->string();
      if (s == "inside")
        clause.side = TrimSide::kInside;
      else if (s == "outside")
        clause.side = TrimSide::kOutside;
      else
        side->fail(fmt::format("expected \"inside\" or \"outside\", got \"{}\"", s));
    } else {
      e.fail("the required key \"side\" is missing: \"inside\" or \"outside\"");
    }
    const int kinds = (e.find("volume") ? 1 : 0) + (e.find("shell") ? 1 : 0) + (e.find("parametric") ? 1 : 0);
    if (kinds != 1) e.fail("a trim clause names exactly one of \"volume\", \"shell\" and \"parametric\"");
    if (const auto v = e.find("volume")) {
      clause.kind = TrimKind::kVolume;
      clause.volume = volume_ref(*v, volumes);
      if (clause.volume == own_volume)
        v->fail(fmt::format("volume \"{}\" is the cell's own volume; a cell is trimmed by other volumes", v->string()));
    } else if (const auto s = e.find("shell")) {
      clause.kind = TrimKind::kShell;
      clause.shell = parse_shell(*s, ctx, "model-space");
    } else {
      clause.kind = TrimKind::kParametric;
      clause.shell = parse_shell(e.at("parametric"), ctx, "parametric");
    }
    trim.clauses.push_back(std::move(clause));
  }
  return trim;
}

}  // namespace trivox::detail
