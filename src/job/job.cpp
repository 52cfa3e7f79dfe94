#include "trivox/job/job.h"

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "job_outputs.h"
#include "job_parts.h"
#include "job_resume.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job_lock.h"
#include "trivox/job/printed_extent.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/detail/material_sheet.h"
#include "trivox/output/detail/stack_parts.h"
#include "trivox/output/layer_writer.h"
#include "trivox/parallel.h"
#include "trivox/version.h"

namespace trivox {

namespace {

std::string rgba_text(const std::array<std::uint8_t, 4>& c) {
  return fmt::format("{},{},{},{}", c[0], c[1], c[2], c[3]);
}

// A file name relative to the output folder with '/' separators on every system.
std::string relative_name(const std::string& name) { return std::filesystem::path(name).generic_string(); }

}  // namespace

int min_layers_of(const JobParams& params) {
  if (params.min_layers) return *params.min_layers;
  const bool voxel_print = std::any_of(params.formats.begin(), params.formats.end(),
                                       [](const std::string& f) { return layer_writer_feeds_voxel_print(f); });
  return voxel_print ? JobParams::kVoxelPrintMinLayers : 0;
}

namespace detail {

LayerRange layer_range(const SliceLayout& L, const JobParams& params) {
  LayerRange r;
  r.first = std::max(0, params.first_layer);
  r.last = params.last_layer < 0 ? L.num_layers - 1 : std::min(params.last_layer, L.num_layers - 1);
  if (r.first > r.last)
    throw Error(fmt::format("layer range {}:{} selects no layer of the {} the model has", params.first_layer + 1,
                            params.last_layer + 1, L.num_layers));
  r.count = r.last - r.first + 1;
  r.padded = std::max(0, min_layers_of(params) - r.count);
  return r;
}

}  // namespace detail

JobManifest job_manifest(const Slicer& slicer, const JobParams& params) {
  const Scene& scene = slicer.scene();
  const SliceLayout& L = slicer.layout();
  const SliceParams& sp = slicer.params();
  const DitherParams& d = slicer.dither_params();
  const detail::LayerRange range = detail::layer_range(L, params);
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
      {"min_layers", fmt::format("{}", min_layers_of(params))},
      {"formats", fmt::format("{}", fmt::join(params.formats, ","))},
      {"preview_layers", fmt::format("{}", fmt::join(params.preview_layers, ","))},
      {"prefix", params.prefix},
      {"background_rgba", rgba_text(job_background(scene, params))},
      {"gcvf", fmt::format("names={} unused={} stl={} bbox={}", params.gcvf.material_codes ? "codes" : "scene",
                           params.gcvf.omit_unused ? "omit" : "list", params.gcvf.mesh_stl, params.gcvf.bounding_box)},
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
  if (min_layers_of(params) < 0 || min_layers_of(params) > JobParams::kMaxMinLayers)
    throw Error(fmt::format("min_layers is {}: a stack is padded to 0 to {} layers", min_layers_of(params),
                            JobParams::kMaxMinLayers));
  // Voxel Print's colour limit holds whatever the printer profile says.
  for (const std::string& format : params.formats)
    if ((format == "voxelprint" || format == "gcvf") &&
        scene.num_materials() > voxel_print_max_materials(scene.printer))
      throw Error(fmt::format(
          "{}: the scene uses {} materials, but GrabCAD Voxel Print (output '{}') prints at most {} per job{} "
          "(printer profile '{}' says {})",
          scene.source, scene.num_materials(), format, voxel_print_max_materials(scene.printer),
          scene.printer.print_mode.empty() ? std::string() : " in " + scene.printer.print_mode + " mode",
          scene.printer.name, scene.printer.max_materials));
  // Voxel Print images tell materials apart by colour alone: the scene and its fields named
  // here, where the writers know neither.
  if (std::any_of(params.formats.begin(), params.formats.end(),
                  [](const std::string& f) { return f == "voxelprint" || f == "gcvf"; })) {
    const auto colour = [](std::array<std::uint8_t, 4> c) {
      return fmt::format("#{:02X}{:02X}{:02X}", c[0], c[1], c[2]);
    };
    const auto opaque = [](std::array<std::uint8_t, 4> c) {
      c[3] = 255;
      return c;
    };
    const std::array<std::uint8_t, 4> background = opaque(job_background(scene, params));
    for (std::size_t b = 0; b < scene.materials.size(); ++b) {
      const std::array<std::uint8_t, 4> c = opaque(scene.materials[b].rgba);
      if (c == background)
        throw Error(fmt::format(
            "{}: /materials/{}: material {} has the image colour {} of the background (--background): Voxel Print "
            "output needs a distinct colour for every material and for the background",
            scene.source, b, shown_name(scene.materials[b].name), colour(c)));
      for (std::size_t a = 0; a < b; ++a)
        if (opaque(scene.materials[a].rgba) == c)
          throw Error(fmt::format(
              "{}: /materials/{}: material {} has the image colour {} of material {} (/materials/{}): Voxel Print "
              "output needs a distinct colour for every material (opaque: the alpha is not part of the image "
              "colour)",
              scene.source, b, shown_name(scene.materials[b].name), colour(c), shown_name(scene.materials[a].name), a));
    }
  }
  // Names are not paths: what goes into a file name keeps every file inside the folder.
  if (const auto problem = file_name_part_problem(params.prefix))
    throw Error(
        fmt::format("the file-name prefix {} cannot be part of a file name: {}", shown_name(params.prefix), *problem));
  for (const std::string& format : params.formats) {
    if (!layer_writer_names_files_by_material(format)) continue;
    for (std::size_t j = 0; j < scene.materials.size(); ++j)
      if (const auto problem = file_name_part_problem(scene.materials[j].name))
        throw Error(
            fmt::format("{}: /materials/{}/name: the material {} names the files of output '{}', so it "
                        "cannot be part of a file name: {}",
                        scene.source, j, shown_name(scene.materials[j].name), format, *problem));
  }
  if (params.shard_count < 1 || params.shard_index < 1 || params.shard_index > params.shard_count)
    throw Error(
        fmt::format("shard {}/{}: shards count from 1 to their number", params.shard_index, params.shard_count));
  if (params.background_rgba && (*params.background_rgba)[3] != 255)
    throw Error(fmt::format("the background's alpha is {}: printer images are opaque, so it must be 255",
                            (*params.background_rgba)[3]));
  const detail::LayerRange range = detail::layer_range(slicer.layout(), params);
  for (int layer : params.preview_layers)
    if (layer < range.first || layer > range.last)
      throw Error(fmt::format("preview layer {} is not among the layers this job slices ({} to {})", layer + 1,
                              range.first + 1, range.last + 1));
}

namespace {

// One run of run_slice_job: its steps share the folder, the manifest, the writers and the
// statistics.
class JobRun {
 public:
  JobRun(const Slicer& slicer, const JobParams& params, ProgressSink* progress)
      : slicer_(slicer),
        params_(params),
        progress_(progress),
        range_(detail::layer_range(slicer.layout(), params)),
        manifest_path_(params.output_dir / manifest_file_name(params.shard_index, params.shard_count)) {}

  // Creates the folder and the manifest; on --resume, keeps the layers whose files are
  // intact and lists the rest as pending.
  void open_folder();
  // The writers of the requested formats and previews; the colour-to-material sheet.
  void make_writers();
  // Slices and writes the pending layers in parallel, recording each in the manifest.
  void slice_layers();
  // The whole-job files, the manifest's final status and stats.json.
  JobStats finish(std::chrono::steady_clock::time_point start);
  // make_writers, slice_layers and finish; whatever fails in them (a full disk, a layer's
  // input) is recorded in the manifest as the job's failure.
  JobStats write(std::chrono::steady_clock::time_point start) {
    try {
      make_writers();
      slice_layers();
      return finish(start);
    } catch (const std::exception& e) {
      mark_failed(e);
      throw;
    }
  }

 private:
  void slice_one(std::size_t task);
  void slice_and_write(std::size_t task);
  void record(int index, std::vector<std::string> written, std::optional<LayerStats> layer_stats,
              const PrintedExtent& printed = {});
  bool stop_requested() const { return cancelled_ || (params_.stop != nullptr && params_.stop->load()); }
  // Records what was completed so that --resume redoes only the rest, once this run has
  // written its manifest (before that, the folder's manifest, if any, is not this run's to
  // change). A full disk leaves no room for it: the space the lock file holds in reserve is
  // given back for this one write. Should even that fail, the previous manifest stands,
  // which is still consistent.
  void mark_failed(const std::exception& e) noexcept;
  // Writes the manifest and keeps the reserve for a failure's manifest at twice its size
  // (layers recorded since the last write make the failure's manifest longer).
  void save_manifest();
  std::vector<std::string> write_layer(int index, const LabelImage& labels, const GreyImage& grey,
                                       bool stacks_only) const;

  // The folder's lock when the caller holds none (JobParams::folder_lock); first, so that it
  // is released last, after the writers have removed their spool files.
  std::optional<JobFolderLock> own_lock_;
  JobFolderLock* lock_ = nullptr;  // own_lock_ or JobParams::folder_lock
  const Slicer& slicer_;
  const JobParams& params_;
  ProgressSink* progress_;
  const detail::LayerRange range_;
  const std::filesystem::path manifest_path_;
  const std::string sheet_name_ = "materials.csv";
  JobManifest manifest_;
  JobStats stats_;
  std::vector<char> kept_;                       // per job layer: kept from the previous run
  std::vector<int> pending_;                     // job layers this run slices
  std::vector<int> refeed_;                      // kept layers fed again to the stack writers
  std::vector<std::vector<std::string>> parts_;  // per job layer: the stack parts a merge of shards kept
  std::vector<std::unique_ptr<LayerWriter>> writers_;
  bool any_stack_ = false;
  // Guards the manifest, the file list, the stats and the progress count, which change
  // together as each layer completes.
  std::mutex record_mutex_;
  int done_ = 0;
  std::atomic<bool> cancelled_{false};  // a layer threw CancelledError
  bool manifest_written_ = false;       // this run has written the manifest
  bool failure_recorded_ = false;
  std::atomic<bool> failed_{false};  // a layer failed (a bad fraction sum): no new layer starts
  std::chrono::steady_clock::time_point last_manifest_write_ = std::chrono::steady_clock::now();
};

void JobRun::open_folder() {
  std::error_code ec;
  // One job per folder: the lock is taken before anything in the folder is read or written.
  if (params_.folder_lock == nullptr) {
    lock_ = &own_lock_.emplace(params_.output_dir, params_.shard_index, params_.shard_count);
  } else {
    lock_ = params_.folder_lock;
    const JobFolderLock& lock = *params_.folder_lock;
    if (std::filesystem::weakly_canonical(lock.dir(), ec) !=
            std::filesystem::weakly_canonical(params_.output_dir, ec) ||
        lock.shard_index() != params_.shard_index || lock.shard_count() != params_.shard_count)
      throw Error(fmt::format("the folder lock held is for {} (shard {}/{}), not for {} (shard {}/{})",
                              lock.dir().string(), lock.shard_index(), lock.shard_count(), params_.output_dir.string(),
                              params_.shard_index, params_.shard_count));
  }
  std::filesystem::create_directories(params_.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create output folder: {}", params_.output_dir.string(), ec.message()));
  manifest_ = job_manifest(slicer_, params_);
  if (params_.resume && std::filesystem::exists(manifest_path_, ec)) {
    const JobManifest previous = read_manifest(manifest_path_);
    std::vector<ManifestFile> intact = detail::intact_files(params_.output_dir, previous);
    // A scene corrected since (after a job stopped at a bad sum) is fine if the correction
    // cannot change the layers kept (manifest.h).
    const std::vector<std::string> diffs = resume_differences(previous, manifest_, detail::layers_of(intact));
    if (!diffs.empty())
      throw Error(
          fmt::format("{}: cannot resume this job: {}; slice into a new folder, or without --resume to start over",
                      manifest_path_.string(), fmt::join(diffs, "; ")));
    remove_stale_temporaries(params_.output_dir, lock_->stale_temporaries());
    manifest_.files = std::move(intact);
    manifest_.printed = detail::printed_of_kept_layers(previous, manifest_.files);
  }
  const int total = range_.total();
  kept_.assign(static_cast<std::size_t>(total), 0);
  for (const ManifestFile& f : manifest_.files) kept_[static_cast<std::size_t>(f.layer - 1)] = 1;  // layers >= 1 only
  parts_ = detail::stack_parts_by_layer(manifest_.files, total);
  for (int index = 0; index < total; ++index)
    if (shard_has_layer(index, params_.shard_index, params_.shard_count) && !kept_[static_cast<std::size_t>(index)])
      pending_.push_back(index);
  for (const ManifestPrinted& p : manifest_.printed) stats_.printed.add(printed_extent(p, range_.first + p.layer - 1));
  stats_.layout = slicer_.layout();
  stats_.padded_layers = range_.padded, stats_.first_layer = range_.first, stats_.last_layer = range_.last;
  stats_.layers_kept = static_cast<int>(std::count(kept_.begin(), kept_.end(), 1));
}

void JobRun::make_writers() {
  const OutputContext ctx = detail::job_output_context(slicer_, params_, params_.output_dir);
  writers_ = detail::job_format_writers(ctx, params_);
  if (!params_.preview_layers.empty()) {
    std::vector<std::pair<int, int>> chosen;
    for (int layer : params_.preview_layers) chosen.emplace_back(layer - range_.first, layer + 1);
    writers_.push_back(make_layer_preview_writer(ctx, std::move(chosen)));
  }
  any_stack_ = std::any_of(writers_.begin(), writers_.end(), [](const auto& w) { return w->needs_whole_stack(); });
  // Stack writers see every model layer; those a resumed job keeps come from their stack
  // parts (after a merge of shards) or are sliced again (the same labels, since a layer
  // depends only on the scene, settings and its index).
  if (any_stack_)
    for (int index = 0; index < range_.total(); ++index)
      if (kept_[static_cast<std::size_t>(index)]) refeed_.push_back(index);
  save_manifest();
  // The colour-to-material sheet depends only on the scene and the settings: written first,
  // listed with the whole-job files when the job completes.
  write_material_sheet(params_.output_dir / sheet_name_, ctx.background_rgba,
                       detail::job_material_sheet(slicer_.scene()));
}

std::vector<std::string> JobRun::write_layer(int index, const LabelImage& labels, const GreyImage& grey,
                                             bool stacks_only) const {
  std::vector<std::string> written;
  for (const auto& w : writers_) {
    if (stacks_only && !w->needs_whole_stack()) continue;
    auto files = write_layer_to(*w, index, labels, grey);
    written.insert(written.end(), files.begin(), files.end());
  }
  return written;
}

// Task t < pending_.size() slices and writes pending layer t; the tasks after them feed the
// stack writers the layers a resumed job kept.
void JobRun::slice_one(std::size_t t) {
  try {
    slice_and_write(t);
  } catch (const CancelledError&) {
    // A stop flag (the job's or the slicer's) ended this layer part way: it is not recorded,
    // no further layer starts, and --resume slices it.
    cancelled_ = true;
  }
}

void JobRun::slice_and_write(std::size_t t) {
  const bool refed = t >= pending_.size();
  const int index = refed ? refeed_[t - pending_.size()] : pending_[t];
  const SliceLayout& L = slicer_.layout();
  if (refed && !parts_[static_cast<std::size_t>(index)].empty()) {
    const detail::StackPart part = detail::read_stack_part(params_.output_dir, parts_[static_cast<std::size_t>(index)],
                                                           L.width_px, L.height_px, slicer_.scene().num_materials());
    write_layer(index, part.labels, part.grey, true);
    return;
  }
  if (index >= range_.count) {  // a padding layer
    const LabelImage empty(L.width_px, L.height_px, LabelImage::kVoid);
    std::vector<std::string> written = write_layer(index, empty, GreyImage(), refed);
    if (!refed) record(index, std::move(written), std::nullopt);
    return;
  }
  std::optional<LayerResult> sliced = detail::slice_layer_unless_failed(slicer_, range_.first + index, failed_);
  if (!sliced) return;
  LayerResult& r = *sliced;
  std::vector<std::string> written = write_layer(index, r.labels, r.grey, refed);
  if (!refed) record(index, std::move(written), std::move(r.stats), printed_extent(r.labels, range_.first + index));
}

void JobRun::record(int index, std::vector<std::string> written, std::optional<LayerStats> layer_stats,
                    const PrintedExtent& printed) {
  std::vector<ManifestFile> entries;
  for (const std::string& name : written) {
    const FileDigest d = sha256_file(params_.output_dir / name);
    entries.push_back({index + 1, relative_name(name), d.bytes, d.sha256});
  }
  std::lock_guard lock(record_mutex_);
  manifest_.files.insert(manifest_.files.end(), entries.begin(), entries.end());
  stats_.files.insert(stats_.files.end(), written.begin(), written.end());
  if (layer_stats) stats_.layers.push_back(std::move(*layer_stats));
  stats_.printed.add(printed);
  if (!printed.empty())
    manifest_.printed.push_back({index + 1, printed.col_lo, printed.col_hi, printed.row_lo, printed.row_hi});
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_manifest_write_).count() >= params_.manifest_interval_seconds) {
    manifest_.sort_files();
    save_manifest();
    last_manifest_write_ = now;
  }
  if (progress_) progress_->on_layer_done(++done_, static_cast<int>(pending_.size()));
}

void JobRun::save_manifest() {
  write_manifest(manifest_path_, manifest_);
  manifest_written_ = true;
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(manifest_path_, ec);
  if (!ec && lock_ != nullptr) lock_->reserve_bytes(2 * bytes + 65536);  // no room: the job goes on without
}

void JobRun::mark_failed(const std::exception& e) noexcept {
  if (!manifest_written_ || failure_recorded_) return;
  failure_recorded_ = true;
  try {
    manifest_.status = JobStatus::kFailed;
    manifest_.message = e.what();
    manifest_.sort_files();
  } catch (const std::exception&) {
    return;
  }
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      write_manifest(manifest_path_, manifest_);
      return;
    } catch (const std::exception&) {
      if (lock_ != nullptr) lock_->release_reserve();
    }
  }
}

void JobRun::slice_layers() {
  stats_.threads = worker_count(params_.threads);
  // One layer per task: layers are independent, so any schedule gives the same files.
  parallel_for_each(
      pending_.size() + refeed_.size(), stats_.threads, [this](std::size_t t) { slice_one(t); },
      [this] { return stop_requested() || failed_.load(); });
  manifest_.sort_files();
  std::sort(stats_.files.begin(), stats_.files.end());
  std::sort(stats_.layers.begin(), stats_.layers.end(),
            [](const LayerStats& a, const LayerStats& b) { return a.layer < b.layer; });
  stats_.interrupted = stop_requested() && (done_ < static_cast<int>(pending_.size()) || any_stack_);
}

JobStats JobRun::finish(std::chrono::steady_clock::time_point start) {
  if (!stats_.interrupted) {
    // Files of the whole job belong to no single layer: the manifest lists them under layer 0.
    std::vector<std::string> whole_job = {sheet_name_};
    for (const auto& w : writers_) {
      const std::vector<std::string> names = w->finish();
      whole_job.insert(whole_job.end(), names.begin(), names.end());
    }
    for (const std::string& name : whole_job) {
      const FileDigest d = sha256_file(params_.output_dir / name);
      manifest_.files.push_back({0, relative_name(name), d.bytes, d.sha256});
      stats_.files.push_back(name);
    }
    manifest_.sort_files();
    std::sort(stats_.files.begin(), stats_.files.end());
    manifest_.status = JobStatus::kComplete;
    // The stack outputs are written: the parts they were made from go, after the manifest
    // that no longer lists them.
    if (any_stack_) detail::take_stack_parts(manifest_.files);
  } else {
    manifest_.status = JobStatus::kInterrupted;
    manifest_.message = fmt::format("stopped after {} of {} layers; continue with --resume", done_, pending_.size());
    if (const std::string note = stack_resume_note(params_); !note.empty()) manifest_.message += "; " + note;
  }
  write_manifest(manifest_path_, manifest_);
  manifest_written_ = true;
  const bool had_parts = std::any_of(parts_.begin(), parts_.end(), [](const auto& p) { return !p.empty(); });
  if (any_stack_ && had_parts && manifest_.status == JobStatus::kComplete)
    detail::remove_stack_parts(params_.output_dir);
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats_.total = sum_layer_stats(stats_.layers, static_cast<std::size_t>(slicer_.scene().num_materials()),
                                 slicer_.scene().cells.size());
  write_stats_json(params_.output_dir / stats_file_name(params_.shard_index, params_.shard_count), slicer_, stats_);
  return std::move(stats_);
}

}  // namespace

// Check, open the folder (resume), make the writers, slice every layer, finish.
JobStats run_slice_job(const Slicer& slicer, const JobParams& params, ProgressSink* progress) {
  const auto start = std::chrono::steady_clock::now();
  check_job_settings(slicer, params);
  JobRun run(slicer, params, progress);
  run.open_folder();
  return run.write(start);
}

}  // namespace trivox
