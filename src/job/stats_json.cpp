// stats.json (FORMATS.md): the job's settings, then per layer and in total the columns of
// the paper's Table 2 and how the pixels were settled. The values are written by walking
// visit_layer_stats (slice_stats.h), so the file and the structs cannot drift apart; the
// total is the job's one sum (JobStats::total).
#include <algorithm>

#include <nlohmann/json.hpp>

#include "trivox/job/job.h"
#include "trivox/job/printed_extent.h"
#include "trivox/output/atomic_file.h"

namespace trivox {

namespace {

using nlohmann::json;

void put_stats(json& j, const LayerStats& s, LayerStatsPart part) {
  visit_layer_stats(s, part, [&j](std::string_view name, const auto& value) { j[std::string(name)] = value; });
}

// The printed extent (whole voxels with a material) beside the model's box, in mm.
json extent_json(const Slicer& slicer, const JobStats& stats) {
  const auto box_json = [](const Box3& b) {
    if (b.empty()) return json(nullptr);
    const Vec3 size = b.size();
    return json{{"size_mm", {size.x, size.y, size.z}},
                {"lo_mm", {b.lo.x, b.lo.y, b.lo.z}},
                {"hi_mm", {b.hi.x, b.hi.y, b.hi.z}}};
  };
  json printed = box_json(printed_box_mm(stats.printed, stats.layout));
  if (!stats.printed.empty())
    printed["voxels"] = {stats.printed.col_hi - stats.printed.col_lo + 1,
                         stats.printed.row_hi - stats.printed.row_lo + 1,
                         stats.printed.layer_hi - stats.printed.layer_lo + 1};
  return {{"printed", printed}, {"model", box_json(slicer.object_bounds())}};
}

}  // namespace

void write_stats_json(const std::filesystem::path& path, const Slicer& slicer, const JobStats& stats) {
  const Scene& scene = slicer.scene();
  const SliceLayout& L = stats.layout;
  json layers = json::array();
  for (const LayerStats& s : stats.layers) {
    json layer = json::object();
    put_stats(layer, s, LayerStatsPart::kLayer);
    // Layers are numbered for a person here, from 1 at the model's bottom, as --layers,
    // --preview and the summary number them (CLI.md, "Layer numbers"); LayerStats::layer and
    // Python's stats keep the 0-based index.
    layer["layer"] = s.layer + 1;
    layers.push_back(std::move(layer));
  }
  json materials = json::array();
  for (const MaterialDef& m : scene.materials) materials.push_back({{"name", m.name}, {"rgba", m.rgba}});
  // Cell names in scene order: the index of pixels_per_cell.
  json cells = json::array();
  for (const Cell& c : scene.cells) cells.push_back(c.name);
  const double n = static_cast<double>(std::max<std::size_t>(1, stats.layers.size()));
  json totals = {{"layers_sliced", stats.layers.size()},
                 {"layers_padded", stats.padded_layers},
                 {"layers_kept", stats.layers_kept},
                 {"interrupted", stats.interrupted},
                 {"threads", stats.threads},
                 {"seconds", stats.seconds},
                 {"seconds_per_layer_mean", stats.total.seconds / n}};
  put_stats(totals, stats.total, LayerStatsPart::kCounts);
  const DitherParams& d = slicer.dither_params();
  const json doc = {{"scene", scene.source},
                    {"printer",
                     {{"name", scene.printer.name},
                      {"x_dpi", scene.printer.x_dpi},
                      {"y_dpi", scene.printer.y_dpi},
                      {"layer_mm", scene.printer.layer_thickness_mm}}},
                    {"tracing", std::string(to_string(slicer.params().tracing))},
                    {"dithering",
                     {{"method", std::string(dither_method_name(d))},
                      {"serpentine", d.serpentine},
                      {"vary_by_layer", d.vary_by_layer},
                      {"skin_voxels", d.skin_voxels}}},
                    {"bitmap",
                     {{"width_px", L.width_px},
                      {"height_px", L.height_px},
                      {"x0_mm", L.x0_mm},
                      {"y_top_mm", L.y_top_mm},
                      {"z0_mm", L.z0_mm}}},
                    {"extent", extent_json(slicer, stats)},
                    {"materials", materials},
                    {"cells", cells},
                    {"total", totals},
                    {"layers", layers}};
  write_file_atomic(path, doc.dump(1) + "\n");
}

}  // namespace trivox
