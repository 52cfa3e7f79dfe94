// The top level of a scene file (docs/SCENE.md): format version, units, printer, materials,
// the fraction policy, dithering and greyscale settings; the cells, each turned into a placed
// Volume and a policy-checked material function, are read by cell_parse.cpp.
#include "trivox/scene/scene.h"

#include <algorithm>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "scene/json_view.h"
#include "scene/scene_parse.h"
#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/printer/material_library.h"

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

std::string detail::read_json_file(const std::filesystem::path& path, std::string_view what,
                                   std::string_view folder_word) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("cannot read the {} file {}: it is a {}", what, path.string(), folder_word));
  // A device or a FIFO is refused by what it is (io/detail/regular_file.h), never read.
  try {
    return read_regular_file(path, std::numeric_limits<std::uint64_t>::max());
  } catch (const IoError& e) {
    throw IoError(fmt::format("cannot read the {} file: {}", what, e.what()));
  }
}

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
    MaterialDef def{name.name("a material"), {}, {}};
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
// "antialiasing": k, "exposure_s": s, "initial_exposure_s": s, "resin": NAME}. A scalar source is built for each cell
// (over the cell's domain) once the cells are read.
void parse_greyscale(const JsonView& node, detail::SceneContext& ctx, Scene& scene) {
  node.expect_object({"source", "curve", "antialiasing", "exposure_s", "initial_exposure_s", "resin"});
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
  // Within what the printer takes (a printer without a mask uses neither: the same limits).
  const MaskedDisplay limits = scene.printer.display.value_or(MaskedDisplay{});
  const auto exposure = [&](const JsonView& v, double lo, double hi) {
    const double s = v.number();
    if (!(s >= lo && s <= hi))
      v.fail(fmt::format("an exposure of {:g} s is outside the {:g} to {:g} s the printer takes", s, lo, hi));
    return s;
  };
  if (const auto e = node.find("exposure_s"))
    def.exposure_s = exposure(*e, limits.min_exposure_s, limits.max_exposure_s);
  if (const auto e = node.find("initial_exposure_s"))
    def.initial_exposure_s = exposure(*e, limits.min_initial_exposure_s, limits.max_initial_exposure_s);
  if (const auto r = node.find("resin")) {
    // One line of config.ini: no control character, and short enough for the printer's screen.
    def.resin = r->name("a resin");
    if (def.resin->size() > 100) r->fail(fmt::format("a resin name of {} bytes; at most 100", def.resin->size()));
  }
  if (!material_source)
    for (Cell& cell : scene.cells) cell.grey_source = detail::parse_scalar(source, ctx, cell.volume.domain());
  scene.greyscale = std::move(def);
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
  SceneReadOptions options;
  options.stop = stop;
  return parse_scene(json_text, source, options);
}

Scene parse_scene(std::string_view json_text, const std::filesystem::path& source, const SceneReadOptions& options) {
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
  ctx.set_stop(options.stop);
  ctx.set_construction_cache(options.construction_cache);
  ctx.set_pixel_mm(scene.printer.finest_pitch_mm());
  std::vector<std::string> names;
  for (const MaterialDef& m : scene.materials) names.push_back(m.name);
  ctx.set_material_names(std::move(names));
  if (const auto v = top.find("volumes")) scene.volumes = detail::parse_volumes(*v, ctx);
  const auto cells = top.find("cells");
  const auto unions = top.find("unions");
  if (!cells && !unions) top.fail("the required key \"cells\" is missing (or give \"unions\")");
  if (cells) detail::parse_cells(*cells, ctx, scene);
  if (unions)
    for (const JsonView& u : unions->elements(1)) detail::parse_union(u, ctx, scene);
  if (const auto g = top.find("greyscale")) parse_greyscale(*g, ctx, scene);
  scene.input_files = ctx.input_files();
  fingerprint(root, scene);
  return scene;
}

Scene read_scene(const std::filesystem::path& path, const std::atomic<bool>* stop) {
  SceneReadOptions options;
  options.stop = stop;
  return read_scene(path, options);
}

Scene read_scene(const std::filesystem::path& path, const SceneReadOptions& options) {
  return parse_scene(detail::read_json_file(path, "scene", "folder"), path, options);
}

}  // namespace trivox
