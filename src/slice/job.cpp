#include "trivox/slice/job.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "tsan_handoff.h"
#include "trivox/error.h"
#include "trivox/output/layer_writer.h"

namespace trivox {

JobStats run_slice_job(const Slicer& slicer, const JobParams& params, ProgressSink* progress) {
  const auto start = std::chrono::steady_clock::now();
  const Scene& scene = slicer.scene();
  const SliceLayout& L = slicer.layout();
  if (scene.num_materials() > scene.printer.max_materials)
    throw Error(fmt::format("{}: the scene uses {} materials but printer profile '{}' takes at most {} per job",
                            scene.source, scene.num_materials(), scene.printer.name, scene.printer.max_materials));
  const int first = std::max(0, params.first_layer);
  const int last = params.last_layer < 0 ? L.num_layers - 1 : std::min(params.last_layer, L.num_layers - 1);
  if (first > last)
    throw Error(fmt::format("layer range {}:{} selects no layer of the {} the model has", params.first_layer,
                            params.last_layer, L.num_layers));

  std::error_code ec;
  std::filesystem::create_directories(params.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create output folder: {}", params.output_dir.string(), ec.message()));

  const int count = last - first + 1;
  JobStats stats;
  stats.layout = L;
  stats.padded_layers = std::max(0, params.min_layers - count);
  const int total_files = count + stats.padded_layers;

  OutputContext ctx;
  ctx.dir = params.output_dir;
  for (const MaterialDef& m : scene.materials) {
    ctx.material_names.push_back(m.name);
    ctx.material_rgba.push_back(m.rgba);
  }
  ctx.background_rgba = params.background_rgba;
  ctx.prefix = params.prefix;
  ctx.total_layers = total_files;
  ctx.png = params.png;
  std::vector<std::unique_ptr<LayerWriter>> writers;
  for (const std::string& f : params.formats) writers.push_back(make_layer_writer(f, ctx));

  stats.layers.resize(static_cast<std::size_t>(count));
  std::vector<std::vector<std::string>> files(static_cast<std::size_t>(total_files));
  std::mutex progress_mutex;
  int done = 0;
  auto write = [&](int index, const LabelImage& labels) {
    for (const auto& w : writers) {
      auto written = w->write_layer(index, labels);
      auto& slot = files[static_cast<std::size_t>(index)];
      slot.insert(slot.end(), written.begin(), written.end());
    }
    if (progress) {
      std::lock_guard lock(progress_mutex);
      progress->on_layer_done(++done, total_files);
    }
  };

  stats.threads = params.threads > 0 ? params.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  tbb::task_arena arena(stats.threads);
  // One layer per task: layers are independent, so any schedule gives the same files.
  // parallel_for keeps a reference to slice_one, so it is made before the tasks are handed
  // their data (tsan_handoff.h).
  auto slice_one = [&](int index) {
    detail::TsanHandoff::task_receives();
    struct PublishAtEnd {
      ~PublishAtEnd() { detail::TsanHandoff::task_publishes(); }
    } publish_at_end;
    if (index < count) {
      LayerResult r = slicer.slice_layer(first + index);
      stats.layers[static_cast<std::size_t>(index)] = std::move(r.stats);
      write(index, r.labels);
    } else {
      write(index, LabelImage(L.width_px, L.height_px, LabelImage::kVoid));
    }
  };
  auto slice_all = [&] { tbb::parallel_for(0, total_files, slice_one); };
  detail::TsanHandoff::caller_publishes();
  arena.execute(slice_all);
  detail::TsanHandoff::caller_receives();
  for (auto& f : files) stats.files.insert(stats.files.end(), f.begin(), f.end());
  std::sort(stats.files.begin(), stats.files.end());
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_stats_json(params.output_dir / "stats.json", slicer, stats);
  return stats;
}

void write_stats_json(const std::filesystem::path& path, const Slicer& slicer, const JobStats& stats) {
  using nlohmann::json;
  const SliceLayout& L = stats.layout;
  json layers = json::array();
  LayerStats total;
  double time_sum = 0;
  total.voxels_per_material.assign(static_cast<std::size_t>(slicer.scene().num_materials()), 0);
  for (const LayerStats& s : stats.layers) {
    const double share = s.pixels_inside > 0 ? 100.0 * static_cast<double>(s.global_calls) / static_cast<double>(s.pixels_inside) : 0.0;
    layers.push_back({{"layer", s.layer}, {"z_mm", s.z_mm}, {"seconds", s.seconds}, {"seconds_inverse", s.seconds_inverse}, {"seconds_material", s.seconds_material}, {"seconds_dither", s.seconds_dither}, {"pixels_total", s.pixels_total},
                      {"pixels_inside", s.pixels_inside}, {"candidates", s.candidates}, {"global_calls", s.global_calls},
                      {"global_share_percent", share}, {"newton_evals", s.newton_evals},
                      {"folded_pixels", s.folded_pixels}, {"unresolved_pixels", s.unresolved_pixels},
                      {"voxels_per_material", s.voxels_per_material}});
    total.pixels_total += s.pixels_total;
    total.pixels_inside += s.pixels_inside;
    total.candidates += s.candidates;
    total.global_calls += s.global_calls;
    total.newton_evals += s.newton_evals;
    total.folded_pixels += s.folded_pixels;
    total.unresolved_pixels += s.unresolved_pixels;
    time_sum += s.seconds;
    for (std::size_t j = 0; j < s.voxels_per_material.size() && j < total.voxels_per_material.size(); ++j)
      total.voxels_per_material[j] += s.voxels_per_material[j];
  }
  json materials = json::array();
  for (const MaterialDef& m : slicer.scene().materials) materials.push_back({{"name", m.name}, {"rgba", m.rgba}});
  const double n = static_cast<double>(std::max<std::size_t>(1, stats.layers.size()));
  json doc = {
      {"scene", slicer.scene().source},
      {"printer", {{"name", slicer.scene().printer.name}, {"x_dpi", slicer.scene().printer.x_dpi},
                   {"y_dpi", slicer.scene().printer.y_dpi}, {"layer_mm", slicer.scene().printer.layer_thickness_mm}}},
      {"tracing", std::string(to_string(slicer.params().tracing))},
      {"bitmap", {{"width_px", L.width_px}, {"height_px", L.height_px}, {"x0_mm", L.x0_mm}, {"y_top_mm", L.y_top_mm},
                  {"z0_mm", L.z0_mm}}},
      {"materials", materials},
      {"total",
       {{"layers_sliced", stats.layers.size()}, {"layers_padded", stats.padded_layers}, {"threads", stats.threads},
        {"seconds", stats.seconds}, {"seconds_per_layer_mean", time_sum / n},
        {"pixels_total", total.pixels_total}, {"pixels_inside", total.pixels_inside},
        {"candidates", total.candidates}, {"global_calls", total.global_calls},
        {"global_share_percent", total.pixels_inside > 0 ? 100.0 * static_cast<double>(total.global_calls) / static_cast<double>(total.pixels_inside) : 0.0},
        {"newton_evals", total.newton_evals}, {"folded_pixels", total.folded_pixels},
        {"unresolved_pixels", total.unresolved_pixels}, {"voxels_per_material", total.voxels_per_material}}},
      {"layers", layers}};
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << doc.dump(1) << '\n';
    if (!out) throw IoError(fmt::format("{}: cannot write", tmp.string()));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace trivox
