#include "harness/pipeline_job.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace trivox::fuzz {

std::uint32_t ByteChoices::u32() {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) {
    v <<= 8;
    if (at_ < data_.size()) v |= data_[at_++];
  }
  return v;
}

double ByteChoices::log_uniform(double lo, double hi) { return lo * std::pow(hi / lo, unit()); }

namespace {

using nlohmann::json;

constexpr std::array<std::string_view, 6> kMaterials = {"VeroCyan",  "VeroMagenta", "VeroYellow",
                                                        "VeroClear", "VeroBlack",   "Agilus30Black"};

// A value of every order of magnitude, of either sign when `signed_values`.
double extreme(ByteChoices& c, double lo, double hi, bool signed_values) {
  const double v = c.log_uniform(lo, hi);
  return signed_values && c.coin() ? -v : v;
}

json printer(ByteChoices& c, bool& resin) {
  resin = false;
  switch (c.pick(7)) {
    case 0: return "j750-hm";
    case 1: return "j750-hq";
    case 2: return "j750-hs";
    case 3: resin = true; return "sl1s";
    case 4:
      return json{
          {"base", "j750-paper"}, {"layer_thickness_mm", c.log_uniform(1e-3, 1.0)}, {"max_materials", 1 + c.pick(10)}};
    case 5:
      return json{{"x_dpi", c.log_uniform(1.0, 1e5)},
                  {"y_dpi", c.log_uniform(1.0, 1e5)},
                  {"layer_thickness_mm", c.log_uniform(1e-4, 10.0)},
                  {"max_materials", 1 + c.pick(10)}};
    default:
      resin = true;
      return json{{"pixel_mm", c.log_uniform(1e-3, 1.0)},
                  {"layer_thickness_mm", c.log_uniform(1e-3, 1.0)},
                  {"max_materials", 1 + c.pick(10)}};
  }
}

// One direction's order and clamped knots on [0, 1]: repeated interior knots up to the order.
json knot_vector(ByteChoices& c, int& order, int& count) {
  // Mostly low orders, sometimes up to 16; order 1 (a volume without interior, which the
  // scene reader refuses) rarely.
  const int kind = c.pick(16);
  order = kind == 15 ? 1 : kind < 4 ? 2 + c.pick(15) : 2 + c.pick(3);
  std::vector<double> knots(static_cast<std::size_t>(order), 0.0);
  const int interior = c.pick(3);
  std::vector<double> breaks;
  for (int i = 0; i < interior; ++i) breaks.push_back(c.pick(3) == 0 ? 0.5 : 0.05 + 0.9 * c.unit());
  std::sort(breaks.begin(), breaks.end());
  for (double b : breaks) {
    const int mult = 1 + c.pick(order);
    for (int m = 0; m < mult; ++m) knots.push_back(b);
  }
  for (int i = 0; i < order; ++i) knots.push_back(1.0);
  count = static_cast<int>(knots.size()) - order;
  return knots;
}

json geometry(ByteChoices& c) {
  std::array<int, 3> orders{}, counts{};
  json knots = json::array();
  for (int d = 0; d < 3; ++d)
    knots.push_back(knot_vector(c, orders[static_cast<std::size_t>(d)], counts[static_cast<std::size_t>(d)]));
  // A box of any size from 1e-6 to 1e6 mm per side, its grid points jittered; some points
  // collapsed onto one, or all of them.
  std::array<double, 3> size{};
  const bool cube = c.coin();
  for (int d = 0; d < 3; ++d) size[static_cast<std::size_t>(d)] = cube && d > 0 ? size[0] : c.log_uniform(1e-6, 1e6);
  const double jitter = c.pick(3) == 0 ? c.unit() : 0.0;
  const int collapse = c.pick(4);  // 0: none, 1: some points onto one, 2: a face's, 3: all
  json points = json::array(), weights = json::array();
  const bool rational = c.coin();
  for (int k = 0; k < counts[2]; ++k)
    for (int j = 0; j < counts[1]; ++j)
      for (int i = 0; i < counts[0]; ++i) {
        const int idx[3] = {i, j, k};
        std::array<double, 3> p{};
        for (int d = 0; d < 3; ++d) {
          const int n = counts[static_cast<std::size_t>(d)];
          const double t = n > 1 ? static_cast<double>(idx[d]) / (n - 1) : 0.5;
          p[static_cast<std::size_t>(d)] =
              size[static_cast<std::size_t>(d)] * (t + jitter * (c.unit() - 0.5) / std::max(1, n - 1));
        }
        if (collapse == 3 || (collapse == 2 && i == 0) || (collapse == 1 && c.pick(4) == 0)) p = {0.0, 0.0, 0.0};
        points.push_back(p);
        if (rational) weights.push_back(c.pick(3) == 0 ? 1.0 : c.log_uniform(1e-6, 1e6));
      }
  json g = {{"orders", orders}, {"knots", knots}, {"points", points}};
  if (rational) g["weights"] = weights;
  return g;
}

json placement(ByteChoices& c) {
  json p = json::object();
  if (c.coin())
    p["translate"] = {extreme(c, 1e-3, 1e308, true), extreme(c, 1e-3, 1e308, true), extreme(c, 1e-3, 1e308, true)};
  if (c.coin()) p["rotate_deg"] = {360.0 * c.unit(), 360.0 * c.unit(), 360.0 * c.unit()};
  if (c.coin()) p["scale"] = c.log_uniform(1e-3, 1e3);
  return p;
}

json fractions(ByteChoices& c, const std::vector<std::string>& materials) {
  json f = json::object();
  double left = 1.0;
  for (const std::string& m : materials) {
    const double v = left * c.unit();
    f[m] = v;
    left -= v;
  }
  return f;
}

json material(ByteChoices& c, const std::vector<std::string>& materials) {
  const std::string& first = materials[static_cast<std::size_t>(c.pick(static_cast<int>(materials.size())))];
  switch (c.pick(8)) {
    case 0: return json{{"kind", "constant"}, {"fractions", fractions(c, materials)}};
    case 1: {
      json f = json::object();
      constexpr std::array<std::string_view, 5> kExpressions = {"u", "0.5 * (1 + sin(2 * pi * x))", "w < 0.5 ? 1 : 0",
                                                                "v * (1 - u)", "0.25"};
      for (const std::string& m : materials)
        f[m] =
            std::string(kExpressions[static_cast<std::size_t>(c.pick(5))]) + " / " + std::to_string(materials.size());
      return json{{"kind", "expression"}, {"fractions", f}};
    }
    case 2: {
      // A linear field in u between two fraction vectors.
      json pts = json::array();
      for (int e = 0; e < 2; ++e) {
        json row = json::array();
        for (std::size_t j = 0; j < materials.size(); ++j)
          row.push_back(c.unit() / static_cast<double>(materials.size()));
        pts.push_back(row);
      }
      return json{{"kind", "spline_field"},
                  {"components", materials},
                  {"field", {{"orders", {2, 1, 1}}, {"knots", {{0, 0, 1, 1}, {0, 1}, {0, 1}}}, {"points", pts}}}};
    }
    case 3:
      return json{{"kind", "porous_tiles"},
                  {"tiles", 1 + c.pick(6)},
                  {"radius", 0.5 * c.unit()},
                  {"materials", {first, c.coin() ? std::string("void") : first}}};
    case 4:
      return json{{"kind", "twisting_curves"},
                  {"points", {{{"uv", {c.unit(), c.unit()}}, {"material", first}}}},
                  {"radius", c.log_uniform(1e-3, 1.0)},
                  {"turns_per_w", 3 * c.unit()}};
    case 5:
      return json{
          {"kind", "scalar_gradient"},
          {"field",
           {{"orders", {2, 2, 2}},
            {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}},
            {"points", {0, 1, 0, 1, 0, 1, 0, 1}}}},
          {"stops", {{{"value", 0.0}, {"fractions", {{first, 1}}}}, {{"value", 1.0}, {"fractions", json::object()}}}}};
    case 6: return "void";
    default: return first;
  }
}

// An ASCII STL of the box [0, s]^3 with a hostile twist: 0 none, 1 every triangle doubled (a
// part exported twice), 2 a stack of coplanar faces over its bottom (each slightly shifted, so
// that no weld joins them), 3 a vertex of two numbers.
std::string trim_stl(ByteChoices& c) {
  const double s = c.log_uniform(1e-3, 1e3);
  const int twist = c.pick(4);
  const double v[8][3] = {{0, 0, 0}, {s, 0, 0}, {0, s, 0}, {s, s, 0}, {0, 0, s}, {s, 0, s}, {0, s, s}, {s, s, s}};
  const int tri[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                          {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  std::string out = "solid fuzz\n";
  const auto facet = [&](const double(&a)[3], const double(&b)[3], const double(&d)[3]) {
    out += "facet normal 0 0 0\nouter loop\n";
    for (const auto* p : {&a, &b, &d})
      out += "vertex " + std::to_string((*p)[0]) + " " + std::to_string((*p)[1]) + " " + std::to_string((*p)[2]) + "\n";
    out += "endloop\nendfacet\n";
  };
  for (int copy = 0; copy < (twist == 1 ? 2 : 1); ++copy)
    for (const auto& t : tri) facet(v[t[0]], v[t[1]], v[t[2]]);
  if (twist == 2) {
    const int layers = 1 + c.pick(3000);
    for (int i = 0; i < layers; ++i) {
      const double d = s * 1e-4 * (i + 1);
      const double a[3] = {d, 0, 0}, b[3] = {s + d, 0, 0}, e[3] = {d, s, 0};
      facet(a, b, e);
    }
  }
  if (twist == 3) out.replace(out.find("vertex"), 6, "vertex 1 2\nvertex");
  return out + "endsolid fuzz\n";
}

// A closed plate extruded: the constructed geometry the construction cache keeps.
json extruded_plate(ByteChoices& c) {
  const double s = c.log_uniform(1e-2, 1e2);
  const json plate = {{"orders", {2, 2}},
                      {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}}},
                      {"points", {{0, 0, 0}, {s, 0, 0}, {0, s, 0}, {s, s, 0}}}};
  return {{"extrude", {{"surface", plate}, {"vector_mm", {0, 0, c.log_uniform(1e-2, 1e2)}}}}};
}

// The hostile inputs of the last choices: a mesh trim from a staged file, a construction cache
// whose entries are damaged before the second read, greyscale settings.
void add_hostile_inputs(ByteChoices& c, json& scene, PipelineJob& job) {
  if (c.pick(3) == 1) {
    job.files.emplace_back("trim.stl", trim_stl(c));
    json shell = {{"mesh", "trim.stl"}, {"inside_rule", c.coin() ? "winding-number" : "even-odd"}};
    if (c.pick(4) == 0) shell["placement"] = placement(c);
    scene["cells"][0]["trim"] = json::array({{{"side", c.coin() ? "inside" : "outside"}, {"shell", shell}}});
  }
  job.cache_damage = c.pick(kCacheDamages);
  if (job.cache_damage != kNoCache) scene["cells"][0]["geometry"] = extruded_plate(c);
  // Greyscale settings of a resin printer: a scalar source that may be NaN or infinite
  // somewhere (the slicer must stop there, naming the cell), exposures in and out of what the
  // printer takes (refused when the scene is read), any anti-aliasing.
  if (scene.contains("greyscale") && c.coin()) {
    constexpr std::array<std::string_view, 6> kSources = {"x",           "u * v + w",   "sqrt(w - 0.5)",
                                                          "1 / (u - u)", "ln(u) + 0.5", "sin(1e6 * x)"};
    json& g = scene["greyscale"];
    g["source"] = std::string(kSources[static_cast<std::size_t>(c.pick(6))]);
    g["curve"] = {{-1, 10 + c.pick(50)}, {1 + c.log_uniform(1e-3, 1e3), 255}};
    g["antialiasing"] = 1 + c.pick(8);
    if (c.coin()) g["exposure_s"] = c.log_uniform(0.1, 1e3);
    if (c.coin()) g["initial_exposure_s"] = c.log_uniform(1.0, 1e4);
  }
}

}  // namespace

PipelineJob generate_pipeline_job(std::span<const std::uint8_t> data) {
  ByteChoices c(data);
  PipelineJob job;
  bool resin = false;
  json scene = {{"version", 1}, {"units", "mm"}, {"printer", printer(c, resin)}};
  std::vector<std::string> materials;
  const int m = 1 + c.pick(4);
  for (int j = 0; j < m; ++j) {
    const std::string name(kMaterials[static_cast<std::size_t>((j + c.pick(2)) % kMaterials.size())]);
    if (std::find(materials.begin(), materials.end(), name) == materials.end()) materials.push_back(name);
  }
  scene["materials"] = materials;
  if (c.coin()) scene["fraction_sums"] = {{"policy", c.coin() ? "normalise" : "error"}};
  if (c.coin()) {
    constexpr std::array<std::string_view, 4> kMethods = {"floyd-steinberg", "jarvis-judice-ninke", "stucki",
                                                          "blue-noise"};
    scene["dithering"] = {{"method", kMethods[static_cast<std::size_t>(c.pick(4))]},
                          {"serpentine", c.coin()},
                          {"vary_by_layer", c.coin()},
                          {"skin_voxels", c.pick(4)}};
  }
  json cells = json::array();
  const int n = 1 + c.pick(2);
  for (int k = 0; k < n; ++k) {
    json cell = {{"name", "cell" + std::to_string(k)}, {"geometry", geometry(c)}, {"material", material(c, materials)}};
    if (c.pick(3) == 0) cell["placement"] = placement(c);
    cells.push_back(cell);
  }
  scene["cells"] = cells;
  if (resin && c.coin())
    scene["greyscale"] = {{"source", {{"material", materials.front()}}},
                          {"curve", {{0, 20 + c.pick(100)}, {1, 255}}},
                          {"antialiasing", 1 + c.pick(3)}};
  job.scene_json = scene.dump();

  constexpr std::array<std::string_view, 6> kTracing = {"none", "previous-point", "previous-line",
                                                        "full", "predict",        "flood"};
  job.tracing = std::string(kTracing[static_cast<std::size_t>(c.pick(6))]);
  if (c.coin()) job.residual_tolerance_mm = c.log_uniform(1e-10, 1e-2);
  if (c.coin()) job.outline_tolerance_mm = c.log_uniform(1e-7, 1.0);
  constexpr std::array<std::string_view, 7> kPrinterFormats = {"voxelprint", "bitmaps", "legacy", "tiff",
                                                               "vdb",        "gcvf",    "preview"};
  constexpr std::array<std::string_view, 3> kResinFormats = {"greyscale", "sl1s", "preview"};
  job.formats.clear();
  const int formats = 1 + c.pick(3);
  for (int f = 0; f < formats; ++f) {
    const std::string name(resin ? kResinFormats[static_cast<std::size_t>(c.pick(3))]
                                 : kPrinterFormats[static_cast<std::size_t>(c.pick(7))]);
    if (std::find(job.formats.begin(), job.formats.end(), name) == job.formats.end()) job.formats.push_back(name);
  }
  job.first_layer_fraction = c.unit();
  job.layer_count = 1 + c.pick(3);
  job.threads = 1 + c.pick(2);
  // Drawn last, so that the choices above mean for an older seed what they meant before.
  add_hostile_inputs(c, scene, job);
  job.scene_json = scene.dump();
  return job;
}

}  // namespace trivox::fuzz
