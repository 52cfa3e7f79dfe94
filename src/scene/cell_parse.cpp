// The cells of a scene file (docs/SCENE.md, "Cells" and "Boolean cells"): each a placed
// Volume, checked for folds, with a policy-checked material function.
#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "scene/json_view.h"
#include "scene/scene_parse.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/material/checked_material.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox::detail {

namespace {

// A cell whose Jacobian determinant changes sign folds over itself: some points have
// several (u,v,w), and the slicer must choose among them. Such a cell is refused when the
// scene is read (the sampled check of jacobian_check.h; left-handed and degenerate cells are
// valid), unless its geometry says "allow_fold": then it is sliced by the fold rules
// (docs/SCENE.md, "Folded cells"). Returns whether the cell folds.
bool check_folds(const Volume& volume, const std::string& cell, const JsonView& geometry, double pixel_mm) {
  const JacobianReport r = checked_jacobian(volume, fmt::format("cell '{}'", cell), geometry, pixel_mm);
  if (r.classification != JacobianClass::kFolded) return false;
  if (geometry_allows_fold(geometry)) return true;
  std::string where;
  for (const FoldRegion& f : fold_regions(volume))
    where += fmt::format("{}u [{:.3g}, {:.3g}] v [{:.3g}, {:.3g}] w [{:.3g}, {:.3g}]", where.empty() ? "" : "; ",
                         f.box.lo.x, f.box.hi.x, f.box.lo.y, f.box.hi.y, f.box.lo.z, f.box.hi.z);
  geometry.fail(
      fmt::format("cell '{}' folds over itself: det J takes both signs ({} of {} samples positive, {} negative, det "
                  "J in [{:g}, {:g}]; the minority sign in {}), so some points have several (u,v,w); set "
                  "\"allow_fold\": true in its geometry to slice it by the fold rules",
                  cell, r.positive, r.positive + r.negative + r.zero, r.negative, r.min_det, r.max_det, where));
}

void add_cell(Scene& scene, SceneContext& ctx, const JsonView& entry, const JsonView& name_field, std::string name,
              Volume volume, const JsonView& material, int scene_volume, Trim trim, bool folds) {
  for (const Cell& other : scene.cells)
    if (other.name == name)
      name_field.fail(fmt::format("the cell name {} is taken by {} already", shown_name(name, '"'), other.pointer));
  auto raw = parse_material(material, ctx, volume.domain());
  MaterialSite site{scene.source, material.pointer(), name, ctx.material_names()};
  auto checked = std::make_shared<CheckedMaterial>(std::move(raw), scene.fraction_policy, std::move(site));
  Cell cell{std::move(name), entry.pointer(), std::move(volume), std::move(checked), scene_volume, std::move(trim)};
  cell.folds = folds;
  scene.cells.push_back(std::move(cell));
}

}  // namespace

void parse_cells(const JsonView& node, SceneContext& ctx, Scene& scene) {
  const std::vector<JsonView> cells = node.elements(1);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    // Between cells as within their constructions and mesh checks: a scene of many cells (each
    // reading its model files) stops at the next cell.
    throw_if_stopped(ctx.stop(), "reading the scene's cells");
    const JsonView& c = cells[i];
    c.expect_object({"name", "geometry", "volume", "placement", "material", "trim"});
    std::string base_name = fmt::format("cell {}", i);
    if (const auto n = c.find("name")) base_name = n->name("a cell");
    const JsonView name_field = c.find("name") ? c.at("name") : c;
    const JsonView material = c.at("material");
    if (const auto named = c.find("volume")) {
      // A cell parametrized by one of the scene's named volumes.
      if (c.find("geometry")) c.fail("give a cell's geometry either as \"geometry\" or as \"volume\", not both");
      if (const auto p = c.find("placement"))
        p->fail("a named volume is placed in \"volumes\"; a cell that names one takes no \"placement\"");
      const int index = volume_ref(*named, scene.volumes);
      Trim trim;
      if (const auto t = c.find("trim")) trim = parse_trim(*t, ctx, scene.volumes, index);
      const SceneVolume& named_volume = scene.volumes[static_cast<std::size_t>(index)];
      add_cell(scene, ctx, c, name_field, base_name, named_volume.volume, material, index, std::move(trim),
               named_volume.folds);
      continue;
    }
    const std::optional<JsonView> placement = c.find("placement");
    for (GeometryPart& part : parse_geometry(c.at("geometry"), ctx)) {
      Volume volume = placement ? parse_and_apply_placement(*placement, part.volume) : std::move(part.volume);
      std::string name = part.label.empty() ? base_name : base_name + "/" + part.label;
      const bool folds = check_folds(volume, name, c.at("geometry"), ctx.pixel_mm());
      Trim trim;
      if (const auto t = c.find("trim")) trim = parse_trim(*t, ctx, scene.volumes, -1);
      add_cell(scene, ctx, c, name_field, std::move(name), std::move(volume), material, -1, std::move(trim), folds);
    }
  }
}

// A "unions" entry: the named volumes it joins and one region per non-empty subset of them,
// each a cell inside the volumes of its subset and outside the others, so the regions are
// mutually exclusive and cover the union (docs/SCENE.md, "Boolean cells").
void parse_union(const JsonView& u, SceneContext& ctx, Scene& scene) {
  u.expect_object({"name", "volumes", "regions"});
  const JsonView name = u.at("name");
  (void)name.name("a union");
  std::vector<int> members;
  const std::vector<JsonView> vols = u.at("volumes").elements(2, 4);
  for (const JsonView& v : vols) {
    const int index = volume_ref(v, scene.volumes);
    if (std::find(members.begin(), members.end(), index) != members.end())
      v.fail(fmt::format("volume \"{}\" is listed twice", v.string()));
    members.push_back(index);
  }
  const auto n = members.size();
  const JsonView regions_node = u.at("regions");
  const std::vector<JsonView> regions = regions_node.elements();
  std::vector<int> seen(std::size_t{1} << n, -1);  // region entry per subset mask
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const JsonView& e = regions[r];
    e.expect_object({"of", "parametrize", "name", "material"});
    unsigned mask = 0;
    std::vector<std::string> names;
    for (const JsonView& v : e.at("of").elements(1, n)) {
      const int index = volume_ref(v, scene.volumes);
      const auto it = std::find(members.begin(), members.end(), index);
      if (it == members.end()) v.fail(fmt::format("volume \"{}\" is not one of the union's \"volumes\"", v.string()));
      const unsigned bit = 1u << (it - members.begin());
      if (mask & bit) v.fail(fmt::format("volume \"{}\" is listed twice", v.string()));
      mask |= bit;
      names.push_back(v.string());
    }
    if (seen[mask] >= 0)
      e.at("of").fail(
          fmt::format("this set of volumes has a region already: {}/{}", regions_node.pointer(), seen[mask]));
    seen[mask] = static_cast<int>(r);
    int param = volume_ref(e.at("of").elements().front(), scene.volumes);
    if (const auto p = e.find("parametrize")) {
      param = volume_ref(*p, scene.volumes);
      const auto it = std::find(members.begin(), members.end(), param);
      if (it == members.end() || !(mask & (1u << (it - members.begin()))))
        p->fail(fmt::format("the region is parametrized by one of its own volumes (\"of\"), not \"{}\"", p->string()));
    }
    Trim trim;
    for (std::size_t k = 0; k < n; ++k) {
      if (members[k] == param) continue;
      TrimClause clause;
      clause.kind = TrimKind::kVolume;
      clause.volume = members[k];
      clause.side = (mask & (1u << k)) ? TrimSide::kInside : TrimSide::kOutside;
      trim.clauses.push_back(clause);
    }
    std::string cell_name = name.string() + "/";
    if (const auto rn = e.find("name")) {
      cell_name += rn->name("a region");
    } else {
      for (std::size_t k = 0; k < names.size(); ++k) cell_name += (k ? "+" : "") + names[k];
    }
    add_cell(scene, ctx, e, e.find("name") ? e.at("name") : e, std::move(cell_name),
             scene.volumes[static_cast<std::size_t>(param)].volume, e.at("material"), param, std::move(trim),
             scene.volumes[static_cast<std::size_t>(param)].folds);
  }
  for (unsigned mask = 1; mask < seen.size(); ++mask)
    if (seen[mask] < 0) {
      std::string set;
      for (std::size_t k = 0; k < n; ++k)
        if (mask & (1u << k))
          set += fmt::format("{}\"{}\"", set.empty() ? "" : ", ",
                             scene.volumes[static_cast<std::size_t>(members[k])].name);
      regions_node.fail(
          fmt::format("no region covers the points inside exactly [{}]; every non-empty set of "
                      "the union's volumes needs one (a region may have the material \"void\")",
                      set));
    }
}

}  // namespace trivox::detail
