#include "trivox/job/slice_job.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/manifest.h"
#include "trivox/material/material_function.h"

namespace trivox {

namespace {

// Bytes of the files a resumed job already has (they need no new space); 0 without a manifest.
std::uint64_t bytes_already_written(const JobParams& job) {
  const auto path = job.output_dir / manifest_file_name(job.shard_index, job.shard_count);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return 0;
  std::uint64_t bytes = 0;
  for (const ManifestFile& f : read_manifest(path).files) bytes += f.bytes;
  return bytes;
}

}  // namespace

SliceParams slice_params_for(SliceParams params, const JobParams& job) {
  // The outline meshes are shared out within the memory limit before they are built.
  params.memory_limit_bytes = job.memory_limit_bytes.value_or(0);
  if (job.stop != nullptr) params.stop = job.stop;  // a stop also ends the set-up and a layer in progress
  return params;
}

void check_bitmap_shows_object(const Slicer& slicer, std::string_view scene_name, bool allow_empty) {
  const SliceLayout& L = slicer.layout();
  if (allow_empty || (L.width_px >= 2 && L.height_px >= 2)) return;
  throw EmptyResultError(
      fmt::format("{}: the object is {} x {} px at printer '{}' (pixels of {:.4f} x {:.4f} mm): a bitmap under 2 "
                  "pixels along x or y cannot show it; is the model in mm? (--allow-empty slices it anyway)",
                  scene_name, L.width_px, L.height_px, slicer.scene().printer.name, L.pitch_x_mm, L.pitch_y_mm));
}

SliceJob::SliceJob(SliceJobParams params) : params_(std::move(params)) {
  const std::filesystem::path& dir = params_.job.output_dir;
  std::error_code ec;
  existed_ = std::filesystem::exists(dir, ec);
  was_empty_ = existed_ && std::filesystem::is_directory(dir, ec) && std::filesystem::is_empty(dir, ec);
  try {
    lock_.emplace(dir, params_.job.shard_index, params_.job.shard_count);
  } catch (const IoError&) {
    // A folder that cannot be created holds no other job: the checks that follow report it
    // (the disk check names the space there), or run_slice_job, which locks it then.
  }
  params_.job.folder_lock = lock_ ? &*lock_ : nullptr;
  // Constructed volumes come from the output folder's cache when an earlier run (or another
  // shard) built them (docs/SLICING.md, "The construction cache").
  if (params_.construction_cache) cache_.emplace(construction_cache_dir(dir));
}

SliceJob::~SliceJob() {
  const std::filesystem::path& dir = params_.job.output_dir;
  const bool roll_back = !kept_ && (!existed_ || was_empty_);
  std::error_code ec;
  // The lock files stay until the lock is released; the construction cache is this job's.
  if (roll_back)
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (!name.starts_with(".trivox") || name == kConstructionCacheFolder)
        std::filesystem::remove_all(entry.path(), ec);
    }
  lock_.reset();                                                 // removes the lock files
  if (roll_back && !existed_) std::filesystem::remove(dir, ec);  // only when nothing else came in
}

std::optional<std::string> SliceJob::lock_taken_over_from() const {
  return lock_ ? lock_->taken_over_from() : std::nullopt;
}

bool SliceJob::locked_by_files() const noexcept { return lock_ && lock_->locked_by_files(); }

Scene SliceJob::read_scene(const std::filesystem::path& path) {
  SceneReadOptions read;
  read.stop = params_.job.stop;
  read.construction_cache = cache_ ? &*cache_ : nullptr;
  return trivox::read_scene(path, read);
}

Scene SliceJob::parse_scene(std::string_view json_text, const std::filesystem::path& source) {
  SceneReadOptions read;
  read.stop = params_.job.stop;
  read.construction_cache = cache_ ? &*cache_ : nullptr;
  return trivox::parse_scene(json_text, source, read);
}

std::vector<std::string> SliceJob::cache_warnings() const {
  return cache_ ? cache_->warnings() : std::vector<std::string>{};
}

int SliceJob::cache_hits() const noexcept { return cache_ ? cache_->hits() : 0; }

SliceParams SliceJob::slice_params(SliceParams params) const {
  return slice_params_for(std::move(params), params_.job);
}

void SliceJob::check_fits(const Slicer& slicer) const {
  if (!params_.checks) return;
  // One sample layer is enough to refuse a job that is far too big; `trivox validate`
  // samples more for a closer estimate.
  JobEstimate estimate = estimate_job(slicer, params_.job, EstimateParams{1});
  if (params_.job.resume) estimate.output_bytes -= std::min(estimate.output_bytes, bytes_already_written(params_.job));
  check_job_fits(estimate, params_.job);
}

JobStats SliceJob::run(const Slicer& slicer, ProgressSink* progress) {
  // A job that fails on its input part way leaves no partial stack behind; one that fails
  // to write (a full disk) or is stopped keeps what it completed for a resume.
  try {
    JobStats stats = run_slice_job(slicer, params_.job, progress);
    kept_ = true;
    return stats;
  } catch (const IoError&) {
    kept_ = true;
    throw;
  } catch (const FractionError&) {
    kept_ = true;
    throw;
  }
}

bool SliceJob::empty_result(const JobStats& stats) const {
  // A resumed job's kept layers, or another shard's, are not counted here; padding layers
  // have no stats.
  return stats.total.pixels_inside == 0 && params_.job.shard_count == 1 && stats.layers_kept == 0 &&
         !stats.layers.empty();
}

void SliceJob::check_result(const JobStats& stats) const {
  if (!empty_result(stats) || params_.allow_empty) return;
  throw EmptyResultError(fmt::format(
      "{}: the stack holds no voxel of the object: no pixel centre of its {} layers lies inside a cell (the "
      "object is thinner than a pixel, or falls between pixel centres); the files are written and {} is complete "
      "(--allow-empty accepts an empty stack)",
      params_.job.output_dir.string(), stats.layers.size(), manifest_path().string()));
}

std::filesystem::path SliceJob::manifest_path() const {
  return params_.job.output_dir / manifest_file_name(params_.job.shard_index, params_.job.shard_count);
}

std::filesystem::path SliceJob::stats_path() const {
  return params_.job.output_dir / stats_file_name(params_.job.shard_index, params_.job.shard_count);
}

}  // namespace trivox
