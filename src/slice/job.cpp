#include "trivox/slice/job.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "output/stack_writers.h"
#include "slice/job_resume.h"
#include "trivox/error.h"
#include "trivox/io/sha256.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/material_sheet.h"
#include "trivox/slice/printed_extent.h"
#include "trivox/version.h"
#include "tsan_handoff.h"

namespace trivox {

namespace {

struct LayerRange {
  int first = 0, last = 0, count = 0;  // model layers first..last
  int padded = 0;                      // empty layers after them
  int total() const noexcept { return count + padded; }
};

LayerRange layer_range(const SliceLayout& L, const JobParams& params) {
  LayerRange r;
  r.first = std::max(0, params.first_layer);
  r.last = params.last_layer < 0 ? L.num_layers - 1 : std::min(params.last_layer, L.num_layers - 1);
  if (r.first > r.last)
    throw Error(fmt::format("layer range {}:{} selects no layer of the {} the model has", params.first_layer + 1,
                            params.last_layer + 1, L.num_layers));
  r.count = r.last - r.first + 1;
  r.padded = std::max(0, params.min_layers - r.count);
  return r;
}

std::string rgba_text(const std::array<std::uint8_t, 4>& c) {
  return fmt::format("{},{},{},{}", c[0], c[1], c[2], c[3]);
}

// A file name relative to the output folder with '/' separators on every system.
std::string relative_name(const std::string& name) { return std::filesystem::path(name).generic_string(); }

// Layers of `previous` whose files all exist with their recorded size and SHA-256.
std::vector<ManifestFile> intact_files(const std::filesystem::path& dir, const JobManifest& previous) {
  std::map<int, std::vector<ManifestFile>> by_layer;
  for (const ManifestFile& f : previous.files)
    if (f.layer > 0) by_layer[f.layer].push_back(f);  // stack files (layer 0) are rewritten at the end
  std::vector<ManifestFile> kept;
  for (auto& [layer, files] : by_layer) {
    const bool intact = std::all_of(files.begin(), files.end(), [&](const ManifestFile& f) {
      std::error_code ec;
      const auto path = dir / f.name;
      if (!std::filesystem::is_regular_file(path, ec) || std::filesystem::file_size(path, ec) != f.bytes || ec)
        return false;
      return sha256_file(path).sha256 == f.sha256;
    });
    if (intact) kept.insert(kept.end(), files.begin(), files.end());
  }
  return kept;
}

}  // namespace

JobManifest job_manifest(const Slicer& slicer, const JobParams& params) {
  const Scene& scene = slicer.scene();
  const SliceLayout& L = slicer.layout();
  const SliceParams& sp = slicer.params();
  const DitherParams& d = slicer.dither_params();
  const LayerRange range = layer_range(L, params);
  JobManifest m;
  m.tool_version = std::string(version());
  m.status = JobStatus::kRunning;
  m.inputs.push_back({"scene", scene.source, scene.source_sha256});
  for (const SceneInputFile& f : scene.input_files) m.inputs.push_back({"model", f.name, f.sha256});
  std::vector<std::string> materials;
  for (const MaterialDef& mat : scene.materials)
    materials.push_back(fmt::format("{}={}", mat.name, rgba_text(mat.rgba)));
  const auto num = [](double x) { return fmt::format("{}", x); };
  m.settings = {
      {"printer", scene.printer.name},
      {"materials", fmt::format("{}", fmt::join(materials, " "))},
      {"bitmap_px", fmt::format("{}x{}", L.width_px, L.height_px)},
      {"origin_mm", fmt::format("{},{},{}", L.x0_mm, L.y_top_mm, L.z0_mm)},
      {"pitch_mm", fmt::format("{},{},{}", L.pitch_x_mm, L.pitch_y_mm, L.layer_mm)},
      {"model_layers", fmt::format("{}", L.num_layers)},
      {"layers", fmt::format("{}:{}", range.first + 1, range.last + 1)},
      {"min_layers", fmt::format("{}", params.min_layers)},
      {"formats", fmt::format("{}", fmt::join(params.formats, ","))},
      {"preview_layers", fmt::format("{}", fmt::join(params.preview_layers, ","))},
      {"prefix", params.prefix},
      {"background_rgba", rgba_text(params.background_rgba)},
      {"png_zlib_level", fmt::format("{}", params.png.zlib_level)},
      {"png_filter", std::string(to_string(params.png.filter))},
      {"png_strategy", std::string(to_string(params.png.strategy))},
      {"tracing", std::string(to_string(sp.tracing))},
      {"newton", fmt::format("tol={} iter={} slack={}", num(sp.newton.residual_tolerance_model),
                             sp.newton.max_iterations, num(sp.newton.outside_slack_relative))},
      {"global", fmt::format("tol={} iter={} slack={} boxes={} same={} singular={}",
                             num(sp.global.newton.residual_tolerance_model), sp.global.newton.max_iterations,
                             num(sp.global.newton.outside_slack_relative), sp.global.max_boxes,
                             num(sp.global.same_root_relative), num(sp.global.singular_relative))},
      {"outline_tolerance_mm", sp.outline_tolerance_mm ? num(*sp.outline_tolerance_mm) : std::string("auto")},
      {"dither", fmt::format("{} serpentine={} vary_by_layer={} skin={} tol={}", dither_method_name(d), d.serpentine,
                             d.vary_by_layer, d.skin_voxels, num(d.fraction_tolerance))},
  };
  m.total_layers = range.total();
  m.shard_index = params.shard_index;
  m.shard_count = params.shard_count;
  m.scene_parts = detail::scene_parts(scene, L, range.first, range.count);
  return m;
}

void check_job_settings(const Slicer& slicer, const JobParams& params) {
  const Scene& scene = slicer.scene();
  if (scene.num_materials() > scene.printer.max_materials)
    throw Error(fmt::format("{}: the scene uses {} materials but printer profile '{}' takes at most {} per job",
                            scene.source, scene.num_materials(), scene.printer.name, scene.printer.max_materials));
  if (params.shard_count < 1 || params.shard_index < 1 || params.shard_index > params.shard_count)
    throw Error(
        fmt::format("shard {}/{}: shards count from 1 to their number", params.shard_index, params.shard_count));
  const LayerRange range = layer_range(slicer.layout(), params);
  for (int layer : params.preview_layers)
    if (layer < range.first || layer > range.last)
      throw Error(fmt::format("preview layer {} is not among the layers this job slices ({} to {})", layer + 1,
                              range.first + 1, range.last + 1));
}

JobStats run_slice_job(const Slicer& slicer, const JobParams& params, ProgressSink* progress) {
  const auto start = std::chrono::steady_clock::now();
  const Scene& scene = slicer.scene();
  const SliceLayout& L = slicer.layout();
  check_job_settings(slicer, params);
  const LayerRange range = layer_range(L, params);
  const int total_files = range.total();

  std::error_code ec;
  std::filesystem::create_directories(params.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create output folder: {}", params.output_dir.string(), ec.message()));

  const std::filesystem::path manifest_path =
      params.output_dir / manifest_file_name(params.shard_index, params.shard_count);
  JobManifest manifest = job_manifest(slicer, params);
  if (params.resume && std::filesystem::exists(manifest_path, ec)) {
    const JobManifest previous = read_manifest(manifest_path);
    std::vector<ManifestFile> intact = intact_files(params.output_dir, previous);
    // A scene corrected since (after a job stopped at a bad sum) is fine if the correction
    // cannot change the layers kept (manifest.h).
    const std::vector<std::string> diffs = resume_differences(previous, manifest, detail::layers_of(intact));
    if (!diffs.empty())
      throw Error(
          fmt::format("{}: cannot resume this job: {}; slice into a new folder, or without --resume to start over",
                      manifest_path.string(), fmt::join(diffs, "; ")));
    remove_stale_temporaries(params.output_dir);
    manifest.files = std::move(intact);
  }
  std::vector<char> kept(static_cast<std::size_t>(total_files), 0);
  for (const ManifestFile& f : manifest.files) kept[static_cast<std::size_t>(f.layer - 1)] = 1;  // layers >= 1 only
  std::vector<int> pending;  // job layers this run slices
  for (int index = 0; index < total_files; ++index)
    if (shard_has_layer(index, params.shard_index, params.shard_count) && !kept[static_cast<std::size_t>(index)])
      pending.push_back(index);

  JobStats stats;
  stats.layout = L;
  stats.padded_layers = range.padded;
  stats.layers_kept = static_cast<int>(std::count(kept.begin(), kept.end(), 1));

  OutputContext ctx;
  ctx.dir = params.output_dir;
  for (const MaterialDef& m : scene.materials) {
    ctx.material_names.push_back(m.name);
    ctx.material_rgba.push_back(m.rgba);
  }
  ctx.background_rgba = params.background_rgba;
  ctx.prefix = params.prefix;
  ctx.total_layers = total_files;
  ctx.model_layers = range.count;
  ctx.pitch_x_mm = L.pitch_x_mm;
  ctx.pitch_y_mm = L.pitch_y_mm;
  ctx.layer_mm = L.layer_mm;
  ctx.x0_mm = L.x0_mm;
  ctx.y_top_mm = L.y_top_mm;
  ctx.z0_mm = L.z0_mm + range.first * L.layer_mm;
  ctx.png = params.png;
  std::vector<std::unique_ptr<LayerWriter>> writers;
  for (const std::string& f : params.formats) writers.push_back(make_layer_writer(f, ctx));
  if (!params.preview_layers.empty()) {
    std::vector<std::pair<int, int>> chosen;
    for (int layer : params.preview_layers) chosen.emplace_back(layer - range.first, layer + 1);
    writers.push_back(detail::make_layer_preview_writer(ctx, std::move(chosen)));
  }
  const bool any_stack =
      std::any_of(writers.begin(), writers.end(), [](const auto& w) { return w->needs_whole_stack(); });
  if (any_stack && params.shard_count > 1)
    throw Error(
        "the stack formats (preview, tiff, vdb, gcvf) need every layer of the job in one run: slice them "
        "without --shard");
  // Stack writers see every model layer; those a resumed job keeps are sliced again for them
  // (the same labels, since a layer depends only on the scene, settings and its index).
  std::vector<int> refeed;
  if (any_stack)
    for (int index = 0; index < total_files; ++index)
      if (kept[static_cast<std::size_t>(index)]) refeed.push_back(index);
  write_manifest(manifest_path, manifest);
  // The colour-to-material sheet depends only on the scene and the settings: written first,
  // listed with the whole-job files when the job completes.
  const std::string sheet_name = "materials.csv";
  {
    std::vector<MaterialSheetRow> sheet;
    for (const MaterialDef& m : scene.materials) sheet.push_back({m.name, m.library, m.rgba});
    write_material_sheet(params.output_dir / sheet_name, params.background_rgba, sheet);
  }

  // Everything below runs under `record_mutex`: the manifest, the file list, the stats and
  // the progress count change together as each layer completes.
  std::mutex record_mutex;
  int done = 0;
  auto last_manifest_write = std::chrono::steady_clock::now();
  auto record = [&](int index, std::vector<std::string> written, std::optional<LayerStats> layer_stats,
                    const PrintedExtent& printed = {}) {
    std::vector<ManifestFile> entries;
    for (const std::string& name : written) {
      const FileDigest d = sha256_file(params.output_dir / name);
      entries.push_back({index + 1, relative_name(name), d.bytes, d.sha256});
    }
    std::lock_guard lock(record_mutex);
    manifest.files.insert(manifest.files.end(), entries.begin(), entries.end());
    stats.files.insert(stats.files.end(), written.begin(), written.end());
    if (layer_stats) stats.layers.push_back(std::move(*layer_stats));
    stats.printed.add(printed);
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_manifest_write).count() >= params.manifest_interval_seconds) {
      manifest.sort_files();
      write_manifest(manifest_path, manifest);
      last_manifest_write = now;
    }
    if (progress) progress->on_layer_done(++done, static_cast<int>(pending.size()));
  };
  auto stop_requested = [&] { return params.stop != nullptr && params.stop->load(); };
  // Set by the first layer that fails (a bad fraction sum): the other workers start no new layer.
  std::atomic<bool> failed{false};
  // Records what was completed so that --resume redoes only the rest. The manifest may be
  // unwritable too (a full disk); the previous one then stands, which is still consistent.
  auto mark_failed = [&](const std::exception& e) {
    manifest.status = JobStatus::kFailed;
    manifest.message = e.what();
    manifest.sort_files();
    try {
      write_manifest(manifest_path, manifest);
    } catch (const std::exception&) {
    }
  };

  stats.threads =
      params.threads > 0 ? params.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  try {
    tbb::task_arena arena(stats.threads);
    // One layer per task: layers are independent, so any schedule gives the same files.
    // parallel_for keeps a reference to slice_one, so it is made before the tasks are handed
    // their data (tsan_handoff.h).
    auto slice_one = [&](std::size_t t) {
      detail::TsanHandoff::task_receives();
      struct PublishAtEnd {
        ~PublishAtEnd() { detail::TsanHandoff::task_publishes(); }
      } publish_at_end;
      if (stop_requested()) return;
      if (t >= pending.size()) {
        const int index = refeed[t - pending.size()];
        std::optional<LayerResult> r;
        if (index < range.count && !(r = detail::slice_layer_unless_failed(slicer, range.first + index, failed)))
          return;
        const LabelImage labels = r ? std::move(r->labels) : LabelImage(L.width_px, L.height_px, LabelImage::kVoid);
        for (const auto& w : writers)
          if (w->needs_whole_stack()) w->write_layer(index, labels);
        return;
      }
      const int index = pending[t];
      std::vector<std::string> written;
      if (index < range.count) {
        std::optional<LayerResult> sliced = detail::slice_layer_unless_failed(slicer, range.first + index, failed);
        if (!sliced) return;
        LayerResult& r = *sliced;
        for (const auto& w : writers) {
          auto files = w->write_layer(index, r.labels);
          written.insert(written.end(), files.begin(), files.end());
        }
        record(index, std::move(written), std::move(r.stats), printed_extent(r.labels, range.first + index));
      } else {
        const LabelImage empty(L.width_px, L.height_px, LabelImage::kVoid);
        for (const auto& w : writers) {
          auto files = w->write_layer(index, empty);
          written.insert(written.end(), files.begin(), files.end());
        }
        record(index, std::move(written), std::nullopt);
      }
    };
    auto slice_all = [&] { tbb::parallel_for(std::size_t{0}, pending.size() + refeed.size(), slice_one); };
    detail::TsanHandoff::caller_publishes();
    arena.execute(slice_all);
    detail::TsanHandoff::caller_receives();
  } catch (const std::exception& e) {
    mark_failed(e);
    throw;
  }
  manifest.sort_files();
  std::sort(stats.files.begin(), stats.files.end());
  std::sort(stats.layers.begin(), stats.layers.end(),
            [](const LayerStats& a, const LayerStats& b) { return a.layer < b.layer; });
  stats.interrupted = stop_requested() && (done < static_cast<int>(pending.size()) || any_stack);
  if (!stats.interrupted) {
    // Files of the whole job belong to no single layer: the manifest lists them under layer 0.
    try {
      std::vector<std::string> whole_job = {sheet_name};
      for (const auto& w : writers) {
        const std::vector<std::string> names = w->finish();
        whole_job.insert(whole_job.end(), names.begin(), names.end());
      }
      for (const std::string& name : whole_job) {
        const FileDigest d = sha256_file(params.output_dir / name);
        manifest.files.push_back({0, relative_name(name), d.bytes, d.sha256});
        stats.files.push_back(name);
      }
    } catch (const std::exception& e) {
      mark_failed(e);
      throw;
    }
    manifest.sort_files();
    std::sort(stats.files.begin(), stats.files.end());
  }
  if (stats.interrupted) {
    manifest.status = JobStatus::kInterrupted;
    manifest.message = fmt::format("stopped after {} of {} layers; continue with --resume", done, pending.size());
  } else {
    manifest.status = JobStatus::kComplete;
  }
  write_manifest(manifest_path, manifest);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string stats_name = params.shard_count > 1
                                     ? fmt::format("stats.shard-{}-of-{}.json", params.shard_index, params.shard_count)
                                     : std::string("stats.json");
  write_stats_json(params.output_dir / stats_name, slicer, stats);
  return stats;
}

namespace {

// The printed extent (whole voxels with a material) beside the model's box, in mm.
nlohmann::json extent_json(const Slicer& slicer, const JobStats& stats) {
  const auto box_json = [](const Box3& b) {
    if (b.empty()) return nlohmann::json(nullptr);
    const Vec3 size = b.size();
    return nlohmann::json{{"size_mm", {size.x, size.y, size.z}},
                          {"lo_mm", {b.lo.x, b.lo.y, b.lo.z}},
                          {"hi_mm", {b.hi.x, b.hi.y, b.hi.z}}};
  };
  nlohmann::json printed = box_json(printed_box_mm(stats.printed, stats.layout));
  if (!stats.printed.empty())
    printed["voxels"] = {stats.printed.col_hi - stats.printed.col_lo + 1,
                         stats.printed.row_hi - stats.printed.row_lo + 1,
                         stats.printed.layer_hi - stats.printed.layer_lo + 1};
  return {{"printed", printed}, {"model", box_json(slicer.scene().bounds())}};
}

}  // namespace

void write_stats_json(const std::filesystem::path& path, const Slicer& slicer, const JobStats& stats) {
  using nlohmann::json;
  const SliceLayout& L = stats.layout;
  json layers = json::array();
  LayerStats total;
  double time_sum = 0;
  total.voxels_per_material.assign(static_cast<std::size_t>(slicer.scene().num_materials()), 0);
  total.pixels_per_cell.assign(slicer.scene().cells.size(), 0);
  for (const LayerStats& s : stats.layers) {
    const double share =
        s.pixels_inside > 0 ? 100.0 * static_cast<double>(s.global_calls) / static_cast<double>(s.pixels_inside) : 0.0;
    layers.push_back({{"layer", s.layer},
                      {"z_mm", s.z_mm},
                      {"seconds", s.seconds},
                      {"seconds_inverse", s.seconds_inverse},
                      {"seconds_material", s.seconds_material},
                      {"seconds_dither", s.seconds_dither},
                      {"pixels_total", s.pixels_total},
                      {"pixels_inside", s.pixels_inside},
                      {"candidates", s.candidates},
                      {"global_calls", s.global_calls},
                      {"global_share_percent", share},
                      {"global_unseeded", s.global_unseeded},
                      {"newton_evals", s.newton_evals},
                      {"guesses", s.guesses},
                      {"guess_misses", s.guess_misses},
                      {"jacobian_steps", s.jacobian_steps},
                      {"slow_path_pixels", s.slow_path_pixels},
                      {"folded_pixels", s.folded_pixels},
                      {"unresolved_pixels", s.unresolved_pixels},
                      {"voxels_per_material", s.voxels_per_material},
                      {"pixels_per_cell", s.pixels_per_cell}});
    total.pixels_total += s.pixels_total;
    total.pixels_inside += s.pixels_inside;
    total.candidates += s.candidates;
    total.global_calls += s.global_calls;
    total.global_unseeded += s.global_unseeded;
    total.newton_evals += s.newton_evals;
    total.guesses += s.guesses;
    total.guess_misses += s.guess_misses;
    total.jacobian_steps += s.jacobian_steps;
    total.slow_path_pixels += s.slow_path_pixels;
    total.folded_pixels += s.folded_pixels;
    total.unresolved_pixels += s.unresolved_pixels;
    time_sum += s.seconds;
    for (std::size_t j = 0; j < s.voxels_per_material.size() && j < total.voxels_per_material.size(); ++j)
      total.voxels_per_material[j] += s.voxels_per_material[j];
    for (std::size_t c = 0; c < s.pixels_per_cell.size() && c < total.pixels_per_cell.size(); ++c)
      total.pixels_per_cell[c] += s.pixels_per_cell[c];
  }
  json materials = json::array();
  for (const MaterialDef& m : slicer.scene().materials) materials.push_back({{"name", m.name}, {"rgba", m.rgba}});
  // Cell names in scene order: the index of pixels_per_cell.
  json cells = json::array();
  for (const Cell& c : slicer.scene().cells) cells.push_back(c.name);
  const double n = static_cast<double>(std::max<std::size_t>(1, stats.layers.size()));
  json doc = {{"scene", slicer.scene().source},
              {"printer",
               {{"name", slicer.scene().printer.name},
                {"x_dpi", slicer.scene().printer.x_dpi},
                {"y_dpi", slicer.scene().printer.y_dpi},
                {"layer_mm", slicer.scene().printer.layer_thickness_mm}}},
              {"tracing", std::string(to_string(slicer.params().tracing))},
              {"dithering",
               {{"method", std::string(dither_method_name(slicer.dither_params()))},
                {"serpentine", slicer.dither_params().serpentine},
                {"vary_by_layer", slicer.dither_params().vary_by_layer},
                {"skin_voxels", slicer.dither_params().skin_voxels}}},
              {"bitmap",
               {{"width_px", L.width_px},
                {"height_px", L.height_px},
                {"x0_mm", L.x0_mm},
                {"y_top_mm", L.y_top_mm},
                {"z0_mm", L.z0_mm}}},
              {"extent", extent_json(slicer, stats)},
              {"materials", materials},
              {"cells", cells},
              {"total",
               {{"layers_sliced", stats.layers.size()},
                {"layers_padded", stats.padded_layers},
                {"layers_kept", stats.layers_kept},
                {"interrupted", stats.interrupted},
                {"threads", stats.threads},
                {"seconds", stats.seconds},
                {"seconds_per_layer_mean", time_sum / n},
                {"pixels_total", total.pixels_total},
                {"pixels_inside", total.pixels_inside},
                {"candidates", total.candidates},
                {"global_calls", total.global_calls},
                {"global_share_percent", total.pixels_inside > 0 ? 100.0 * static_cast<double>(total.global_calls) /
                                                                       static_cast<double>(total.pixels_inside)
                                                                 : 0.0},
                {"global_unseeded", total.global_unseeded},
                {"newton_evals", total.newton_evals},
                {"guesses", total.guesses},
                {"guess_misses", total.guess_misses},
                {"jacobian_steps", total.jacobian_steps},
                {"slow_path_pixels", total.slow_path_pixels},
                {"folded_pixels", total.folded_pixels},
                {"unresolved_pixels", total.unresolved_pixels},
                {"voxels_per_material", total.voxels_per_material},
                {"pixels_per_cell", total.pixels_per_cell}}},
              {"layers", layers}};
  write_file_atomic(path, doc.dump(1) + "\n");
}

}  // namespace trivox
