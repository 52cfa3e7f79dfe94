// The top level of a scene file (docs/SCENE.md): format version, units, printer, materials,
// the fraction policy, and the cells, each turned into a placed Volume and a policy-checked
// material function.
#include "trivox/scene/scene.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>

#include <fmt/format.h>

#include "scene/json_view.h"
#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/material/checked_material.h"
#include "trivox/printer/material_library.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {

using detail::Json;
using detail::JsonView;

int Scene::material_index(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  return kVoidMaterial;
}

Box3 Scene::bounds() const noexcept {
  Box3 box;
  for (const Cell& c : cells) box.expand(c.volume.bounds());
  return box;
}

namespace {

// nlohmann's parser keeps the last of two equal keys without a word; a repeated key in a
// scene is a typo that would silently drop a setting, so the parse callback rejects it.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& source) : source_(&source) {}

  bool operator()(int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start: frames_.push_back({false, 0, {}, {}}); break;
      case Json::parse_event_t::array_start: frames_.push_back({true, 0, {}, {}}); break;
      case Json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw InputError(*source_, 0, pointer_to_top(),
                           fmt::format("the key \"{}\" appears twice in this object", top.key));
        break;
      }
      case Json::parse_event_t::value: element_done(); break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        frames_.pop_back();
        element_done();
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array;
    std::size_t index;
    std::string key;
    std::set<std::string> keys;
  };

  void element_done() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  std::string pointer_to_top() const {
    std::string p;
    for (std::size_t i = 0; i + 1 < frames_.size(); ++i)
      p += "/" + (frames_[i].array ? std::to_string(frames_[i].index) : frames_[i].key);
    return p;
  }

  const std::string* source_;
  std::vector<Frame> frames_;
};

}  // namespace

Json detail::parse_json_text(std::string_view text, const std::string& source) {
  try {
    return Json::parse(text.begin(), text.end(), DuplicateKeyCheck(source));
  } catch (const Json::parse_error& e) {
    const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), '\n');
    throw InputError(source, static_cast<int>(line), "", fmt::format("invalid JSON: {}", e.what()));
  } catch (const Json::exception& e) {
    // Not a syntax error but a value the parser cannot hold (a number beyond the range of a
    // double, "1e999"); nlohmann names the text but not where it is, so the line is that of
    // the first occurrence of the quoted text.
    const std::string what = e.what();
    int line = 0;
    const auto open = what.find('\''), close = what.rfind('\'');
    if (open != std::string::npos && close > open + 1) {
      const auto at = text.find(std::string_view(what).substr(open + 1, close - open - 1));
      if (at != std::string_view::npos)
        line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    }
    throw InputError(source, line, "", fmt::format("invalid JSON: {}", what));
  }
}

namespace {

double positive(const JsonView& v) {
  const double x = v.number();
  if (!(x > 0.0)) v.fail(fmt::format("{} is not > 0", x));
  return x;
}

PrinterProfile builtin(const JsonView& name) {
  try {
    return builtin_printer_profile(name.string());
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    name.fail(e.what());
  }
}

PrinterProfile parse_printer(const JsonView& node) {
  if (node.is_string()) return builtin(node);
  node.expect_object({"name", "base", "x_dpi", "y_dpi", "pixel_mm", "layer_thickness_mm", "max_materials"});
  PrinterProfile p;
  const auto base = node.find("base");
  const auto pixel = node.find("pixel_mm");
  if (pixel && (node.find("x_dpi") || node.find("y_dpi")))
    pixel->fail("give either \"pixel_mm\" (square pixels) or \"x_dpi\" and \"y_dpi\", not both");
  if (base) {
    p = builtin(*base);
  } else {
    p.name = "custom";
    for (std::string_view key : {"x_dpi", "y_dpi", "layer_thickness_mm", "max_materials"})
      if (!node.find(key) && !(pixel && (key == "x_dpi" || key == "y_dpi")))
        node.fail(
            fmt::format("the required key \"{}\" is missing (or give a built-in profile as "
                        "\"base\")",
                        key));
  }
  if (const auto v = node.find("name")) p.name = v->string();
  if (pixel) p.x_dpi = p.y_dpi = 25.4 / positive(*pixel);
  if (const auto v = node.find("x_dpi")) p.x_dpi = positive(*v);
  if (const auto v = node.find("y_dpi")) p.y_dpi = positive(*v);
  if (const auto v = node.find("layer_thickness_mm")) p.layer_thickness_mm = positive(*v);
  if (const auto v = node.find("max_materials")) p.max_materials = v->integer_in(1, kMaxMaterials);
  try {
    p.validate();
  } catch (const Error& e) {
    node.fail(e.what());
  }
  return p;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::array<std::uint8_t, 4> parse_rgba(const JsonView& node) {
  std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
  if (node.is_string()) {
    const std::string& s = node.string();
    const bool ok_size = s.size() == 7 || s.size() == 9;
    bool ok = ok_size && s[0] == '#';
    for (std::size_t i = 1; ok && i < s.size(); ++i) ok = hex_digit(s[i]) >= 0;
    if (!ok) node.fail(fmt::format("\"{}\" is not a colour \"#RRGGBB\" or \"#RRGGBBAA\" (hexadecimal)", s));
    for (std::size_t c = 0; 2 * c + 1 < s.size(); ++c)
      rgba[c] = static_cast<std::uint8_t>(16 * hex_digit(s[2 * c + 1]) + hex_digit(s[2 * c + 2]));
    return rgba;
  }
  if (!node.is_array())
    node.fail(fmt::format("expected [r, g, b, a] (integers 0 to 255) or \"#RRGGBBAA\", got {}",
                          JsonView::describe(node.json())));
  const std::vector<JsonView> c = node.elements(3, 4);
  for (std::size_t i = 0; i < c.size(); ++i) rgba[i] = static_cast<std::uint8_t>(c[i].integer_in(0, 255));
  return rgba;
}

std::vector<MaterialDef> parse_materials(const JsonView& node, const PrinterProfile& printer) {
  std::vector<MaterialDef> materials;
  for (const JsonView& e : node.elements(1)) {
    // A plain string names a library material; an object may leave out the colour of one.
    const bool named_only = e.is_string();
    if (!named_only) e.expect_object({"name", "rgba", "description"});
    const JsonView name = named_only ? e : e.at("name");
    MaterialDef def{name.string(), {}, {}};
    if (def.name.empty()) name.fail("a material name must not be empty");
    const std::optional<LibraryMaterial> known = find_library_material(def.name);
    if (known) def.library = std::string(known->name);
    const std::optional<JsonView> rgba = named_only ? std::nullopt : e.find("rgba");
    if (rgba) {
      def.rgba = parse_rgba(*rgba);
    } else if (known) {
      def.rgba = known->rgba;
      if (named_only) def.name = def.library;
    } else {
      std::string list;
      for (const LibraryMaterial& m : material_library()) list += fmt::format("{}{}", list.empty() ? "" : ", ", m.name);
      (named_only ? e : e.at("name"))
          .fail(fmt::format("{} is not a library material, so it needs an \"rgba\" colour; the library "
                            "materials are {}",
                            shown_name(def.name, '"'), list));
    }
    if (def.name == "void") name.fail("\"void\" is reserved for no material and needs no entry");
    for (std::size_t i = 0; i < materials.size(); ++i)
      if (materials[i].name == def.name)
        name.fail(fmt::format("material {} is declared already as /materials/{}", shown_name(def.name, '"'), i));
    if (!named_only)
      if (const auto d = e.find("description")) d->string();
    materials.push_back(std::move(def));
  }
  if (static_cast<int>(materials.size()) > printer.max_materials)
    node.fail(fmt::format("the scene declares {} materials; printer \"{}\" takes at most {} per job", materials.size(),
                          printer.name, printer.max_materials));
  return materials;
}

FractionPolicy parse_policy(const JsonView& node) {
  node.expect_object({"policy", "tolerance"});
  FractionPolicy policy;
  if (const auto p = node.find("policy")) {
    const std::string& s = p->string();
    if (s == "error")
      policy.policy = SumPolicy::kError;
    else if (s == "normalise" || s == "normalize")
      policy.policy = SumPolicy::kNormalise;
    else
      p->fail(fmt::format("expected \"error\" or \"normalise\", got \"{}\"", s));
  }
  if (const auto t = node.find("tolerance")) {
    policy.tolerance = t->number();
    if (policy.tolerance < 0.0 || policy.tolerance >= 1.0)
      t->fail(fmt::format("the tolerance {} is not in [0, 1)", policy.tolerance));
  }
  return policy;
}

DitherParams parse_dithering(const JsonView& node) {
  node.expect_object({"method", "serpentine", "vary_by_layer", "skin_voxels"});
  DitherParams params;
  if (const auto m = node.find("method")) {
    if (!set_dither_method(m->string(), params)) {
      std::string list;
      for (std::string_view n : dither_method_names()) list += fmt::format("{}\"{}\"", list.empty() ? "" : ", ", n);
      m->fail(fmt::format("unknown dithering method \"{}\"; the methods are {}", m->string(), list));
    }
  }
  if (const auto s = node.find("serpentine")) params.serpentine = s->boolean();
  if (const auto v = node.find("vary_by_layer")) params.vary_by_layer = v->boolean();
  if (const auto k = node.find("skin_voxels")) params.skin_voxels = k->integer_in(0, DitherParams::kMaxSkinVoxels);
  return params;
}

// "greyscale": {"source": {"material": NAME} or a scalar source, "curve": [[value, grey], ...],
// "antialiasing": k, "exposure_s": s, "initial_exposure_s": s}. A scalar source is built for each cell (over the cell's
// domain) once the cells are read.
void parse_greyscale(const JsonView& node, detail::SceneContext& ctx, Scene& scene) {
  node.expect_object({"source", "curve", "antialiasing", "exposure_s", "initial_exposure_s"});
  GreyscaleDef def;
  const JsonView source = node.at("source");
  const bool material_source = source.is_object() && source.find("material");
  if (material_source) {
    source.expect_object({"material"});
    const JsonView name = source.at("material");
    def.material = scene.material_index(name.string());
    if (def.material < 0)
      name.fail(
          fmt::format("\"{}\" is not a declared material (the greyscale source names one material, not "
                      "\"void\")",
                      name.string()));
  }
  std::vector<GreyPoint> points;
  for (const JsonView& pair : node.at("curve").elements(1)) {
    const std::vector<JsonView> vg = pair.elements(2, 2);
    points.push_back({vg[0].number(), vg[1].number()});
  }
  try {
    def.curve = GreyCalibration(std::move(points));
  } catch (const Error& e) {
    node.at("curve").fail(e.what());
  }
  if (const auto k = node.find("antialiasing")) def.antialiasing = k->integer_in(1, 8);
  if (const auto e = node.find("exposure_s")) def.exposure_s = positive(*e);
  if (const auto e = node.find("initial_exposure_s")) def.initial_exposure_s = positive(*e);
  if (!material_source)
    for (Cell& cell : scene.cells) cell.grey_source = detail::parse_scalar(source, ctx, cell.volume.domain());
  scene.greyscale = std::move(def);
}

// A cell whose Jacobian determinant changes sign folds over itself: some points have
// several (u,v,w), and the slicer must choose among them. Such a cell is refused when the
// scene is read (the sampled check of jacobian_check.h; left-handed and degenerate cells are
// valid), unless its geometry says "allow_fold": then it is sliced by the fold rules
// (docs/SCENE.md, "Folded cells"). Returns whether the cell folds.
bool check_folds(const Volume& volume, const std::string& cell, const JsonView& geometry, double pixel_mm) {
  const JacobianReport r = check_jacobian(volume);
  detail::refuse_without_interior(volume, r, fmt::format("cell '{}'", cell), geometry, pixel_mm);
  if (r.classification != JacobianClass::kFolded) return false;
  if (detail::geometry_allows_fold(geometry)) return true;
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

void add_cell(Scene& scene, detail::SceneContext& ctx, const JsonView& entry, const JsonView& name_field,
              std::string name, Volume volume, const JsonView& material, int scene_volume, Trim trim, bool folds) {
  for (const Cell& other : scene.cells)
    if (other.name == name)
      name_field.fail(fmt::format("the cell name {} is taken by {} already", shown_name(name, '"'), other.pointer));
  auto raw = detail::parse_material(material, ctx, volume.domain());
  MaterialSite site{scene.source, material.pointer(), name, ctx.material_names()};
  auto checked = std::make_shared<CheckedMaterial>(std::move(raw), scene.fraction_policy, std::move(site));
  Cell cell{std::move(name), entry.pointer(), std::move(volume), std::move(checked), scene_volume, std::move(trim)};
  cell.folds = folds;
  scene.cells.push_back(std::move(cell));
}

void parse_cells(const JsonView& node, detail::SceneContext& ctx, Scene& scene) {
  const std::vector<JsonView> cells = node.elements(1);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const JsonView& c = cells[i];
    c.expect_object({"name", "geometry", "volume", "placement", "material", "trim"});
    std::string base_name = fmt::format("cell {}", i);
    if (const auto n = c.find("name")) {
      base_name = n->string();
      if (base_name.empty()) n->fail("a cell name must not be empty");
    }
    const JsonView name_field = c.find("name") ? c.at("name") : c;
    const JsonView material = c.at("material");
    if (const auto named = c.find("volume")) {
      // A cell parametrized by one of the scene's named volumes.
      if (c.find("geometry")) c.fail("give a cell's geometry either as \"geometry\" or as \"volume\", not both");
      if (const auto p = c.find("placement"))
        p->fail("a named volume is placed in \"volumes\"; a cell that names one takes no \"placement\"");
      const int index = detail::volume_ref(*named, scene.volumes);
      Trim trim;
      if (const auto t = c.find("trim")) trim = detail::parse_trim(*t, ctx, scene.volumes, index);
      const SceneVolume& named_volume = scene.volumes[static_cast<std::size_t>(index)];
      add_cell(scene, ctx, c, name_field, base_name, named_volume.volume, material, index, std::move(trim),
               named_volume.folds);
      continue;
    }
    const std::optional<JsonView> placement = c.find("placement");
    for (detail::GeometryPart& part : detail::parse_geometry(c.at("geometry"), ctx)) {
      Volume volume = placement ? detail::parse_and_apply_placement(*placement, part.volume) : std::move(part.volume);
      std::string name = part.label.empty() ? base_name : base_name + "/" + part.label;
      const bool folds = check_folds(volume, name, c.at("geometry"), ctx.pixel_mm());
      Trim trim;
      if (const auto t = c.find("trim")) trim = detail::parse_trim(*t, ctx, scene.volumes, -1);
      add_cell(scene, ctx, c, name_field, std::move(name), std::move(volume), material, -1, std::move(trim), folds);
    }
  }
}

// A "unions" entry: the named volumes it joins and one region per non-empty subset of them,
// each a cell inside the volumes of its subset and outside the others, so the regions are
// mutually exclusive and cover the union (docs/SCENE.md, "Boolean cells").
void parse_union(const JsonView& u, detail::SceneContext& ctx, Scene& scene) {
  u.expect_object({"name", "volumes", "regions"});
  const JsonView name = u.at("name");
  if (name.string().empty()) name.fail("a union name must not be empty");
  std::vector<int> members;
  const std::vector<JsonView> vols = u.at("volumes").elements(2, 4);
  for (const JsonView& v : vols) {
    const int index = detail::volume_ref(v, scene.volumes);
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
      const int index = detail::volume_ref(v, scene.volumes);
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
    int param = detail::volume_ref(e.at("of").elements().front(), scene.volumes);
    if (const auto p = e.find("parametrize")) {
      param = detail::volume_ref(*p, scene.volumes);
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
      if (rn->string().empty()) rn->fail("a region name must not be empty");
      cell_name += rn->string();
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

// The scene's fingerprints (Scene::settings_fingerprint, Cell::fingerprint), from the parsed
// JSON, canonical: the scene keeps its keys in file order, so the parts are dumped with their
// keys sorted (nlohmann::json's objects), and whitespace, key order and the spelling of a
// number in the file do not matter.
std::string canonical(const Json& part) { return nlohmann::json::parse(part.dump()).dump(); }

void fingerprint(const Json& root, Scene& scene) {
  Json settings = root;
  for (const char* key : {"cells", "unions", "volumes", "description", "$schema", "fraction_sums"}) settings.erase(key);
  scene.settings_fingerprint = sha256_hex(canonical(settings));
  const auto at = [&](const std::string& pointer) { return canonical(root.at(Json::json_pointer(pointer))); };
  for (Cell& cell : scene.cells) {
    std::string text = fmt::format("{}\n{}", cell.name, at(cell.pointer));
    if (cell.scene_volume >= 0)
      text += fmt::format("\nvolume {}", at(scene.volumes[static_cast<std::size_t>(cell.scene_volume)].pointer));
    for (const TrimClause& k : cell.trim.clauses) {
      text += fmt::format("\ntrim {} {}", static_cast<int>(k.kind), static_cast<int>(k.side));
      if (k.kind == TrimKind::kVolume)
        text += fmt::format(" {}", at(scene.volumes[static_cast<std::size_t>(k.volume)].pointer));
    }
    cell.fingerprint = sha256_hex(text);
  }
}

}  // namespace

Scene parse_scene(std::string_view json_text, const std::filesystem::path& source, const std::atomic<bool>* stop) {
  const std::string src = source.string();
  const Json root = detail::parse_json_text(json_text, src);
  const JsonView top(root, "", src);
  top.expect_object({"$schema", "version", "description", "units", "printer", "materials", "fraction_sums", "dithering",
                     "greyscale", "volumes", "cells", "unions"});
  if (const auto v = top.find("version"); v && v->integer() != 1)
    v->fail(fmt::format("this is scene format version {}; trivox reads version 1", v->integer()));
  if (const auto d = top.find("description")) d->string();
  if (const auto s = top.find("$schema")) s->string();
  const JsonView units = top.at("units");
  if (units.string() != "mm")
    units.fail(fmt::format("units \"{}\" are not supported: scenes are in millimetres, \"mm\"", units.string()));

  Scene scene;
  scene.source = src;
  scene.source_sha256 = sha256_hex(json_text);
  scene.printer = parse_printer(top.at("printer"));
  scene.materials = parse_materials(top.at("materials"), scene.printer);
  if (const auto p = top.find("fraction_sums")) scene.fraction_policy = parse_policy(*p);
  if (const auto d = top.find("dithering")) scene.dithering = parse_dithering(*d);

  detail::SceneContext ctx(src, source.parent_path());
  ctx.set_stop(stop);
  ctx.set_pixel_mm(
      std::min({scene.printer.pitch_x_mm(), scene.printer.pitch_y_mm(), scene.printer.layer_thickness_mm}));
  std::vector<std::string> names;
  for (const MaterialDef& m : scene.materials) names.push_back(m.name);
  ctx.set_material_names(std::move(names));
  if (const auto v = top.find("volumes")) scene.volumes = detail::parse_volumes(*v, ctx);
  const auto cells = top.find("cells");
  const auto unions = top.find("unions");
  if (!cells && !unions) top.fail("the required key \"cells\" is missing (or give \"unions\")");
  if (cells) parse_cells(*cells, ctx, scene);
  if (unions)
    for (const JsonView& u : unions->elements(1)) parse_union(u, ctx, scene);
  if (const auto g = top.find("greyscale")) parse_greyscale(*g, ctx, scene);
  scene.input_files = ctx.input_files();
  fingerprint(root, scene);
  return scene;
}

Scene read_scene(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("cannot read the scene file {}: it is a folder", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot open the scene file {}", path.string()));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(fmt::format("cannot read the scene file {}", path.string()));
  return parse_scene(text, path, stop);
}

}  // namespace trivox
