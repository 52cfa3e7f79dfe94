// One slicing job from start to end, as `trivox slice` and the Python module's slice() run
// it (docs/CLI.md, "slice"; docs/PYTHON.md, "Slicing"): the output folder locked before the
// scene is read, the scene read through the folder's construction cache, the estimate and
// its checks, run_slice_job (job.h), and the rule that refuses a stack without the object.
//
// The steps are separate calls, in this order, so that a caller can report between them
// (the library never prints): construct (lock), read_scene, make the Slicer from
// slice_params(), check_fits, run, check_result.
//
// A job that fails for a reason a resume cannot mend (a scene that does not read, a setting
// the job cannot take) must not leave a half-written stack that looks like a result: when the
// SliceJob is destroyed without run() having returned or failed to write, the folder is put
// back as it was found when it was absent or empty (a folder that already held files is left
// alone: they are not this job's to delete). A write error (IoError) or a fraction sum that
// breaks the rule (FractionError) keeps the completed layers: the manifest then says the job
// failed, and a resume finishes it. The files are removed while the lock is still held, so
// that they cannot be another job's; the lock files go when the lock is released.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/job/job.h"
#include "trivox/job/job_lock.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slice_params.h"

namespace trivox {

struct SliceJobParams {
  // The folder, the layers, the formats, the shard, resume, the stop flag, the memory limit
  // (JobParams::memory_limit_bytes, the one way it enters); folder_lock is the job's own.
  JobParams job;
  // Read the scene through DIR/.trivox-cache (construction_cache_dir()); false: build every
  // constructed volume, neither reading nor writing the cache.
  bool construction_cache = true;
  // Before the first layer, estimate the job from one sample layer and refuse it
  // (check_job_fits) when the disk or the memory limit cannot take it.
  bool checks = true;
  // A stack without the object is a result, not an error (check_result()).
  bool allow_empty = false;
};

// `params` for a slicer of the job `job`: its memory limit for the outline meshes
// (SliceParams::memory_limit_bytes, 0 without one) and its stop flag, when it has one.
SliceParams slice_params_for(SliceParams params, const JobParams& job);

// Throws EmptyResultError, unless allow_empty, when the bitmap of `slicer`'s layout is under 2
// pixels along x or y: the object is smaller than the printer's pixels (a model in metres read
// as millimetres). `scene_name` names the scene in the message. Checked before anything is
// written, by `trivox slice`, `trivox validate` and the Python module's jobs, before
// SliceJob::check_fits.
void check_bitmap_shows_object(const Slicer& slicer, std::string_view scene_name, bool allow_empty);

class SliceJob {
 public:
  // Takes the output folder's lock (job_lock.h), creating the folder: throws Error when
  // another job holds it. A folder that cannot be created is not an error here: the checks,
  // or run_slice_job, which locks it then, report it.
  explicit SliceJob(SliceJobParams params);
  ~SliceJob();  // rolls the folder back unless run() kept it (above), then releases the lock
  SliceJob(const SliceJob&) = delete;
  SliceJob& operator=(const SliceJob&) = delete;

  const SliceJobParams& params() const noexcept { return params_; }
  // The holder line of a lock a job that ended without releasing it left behind; nullopt
  // when there was none.
  std::optional<std::string> lock_taken_over_from() const;
  // The folder's file system has no flock locks: its lock files alone lock it
  // (JobFolderLock::locked_by_files).
  bool locked_by_files() const noexcept;

  // The scene, read (or parsed from `json_text`) through the construction cache unless
  // disabled; stop: JobParams::stop.
  Scene read_scene(const std::filesystem::path& path);
  Scene parse_scene(std::string_view json_text, const std::filesystem::path& source);
  // What the construction cache reported while the scene was read: damaged or unusable
  // entries, and the volumes it supplied. Empty and 0 without a cache.
  std::vector<std::string> cache_warnings() const;
  int cache_hits() const noexcept;
  std::filesystem::path cache_dir() const { return construction_cache_dir(params_.job.output_dir); }

  // slice_params_for(params, this job).
  SliceParams slice_params(SliceParams params) const;
  // With checks: estimates the job from one sample layer (less the files a resumed job
  // already has) and throws Error when it does not fit (check_job_fits). Without, nothing.
  void check_fits(const Slicer& slicer) const;
  // run_slice_job into the locked folder. Keeps the folder (no rollback) once it returns,
  // and when it throws IoError or FractionError.
  JobStats run(const Slicer& slicer, ProgressSink* progress = nullptr);
  // True when a job that sliced every model layer itself (one shard, nothing kept from a
  // previous run) found no voxel of the object: the object is lost.
  bool empty_result(const JobStats& stats) const;
  // Throws EmptyResultError for an empty result (above) unless allow_empty.
  void check_result(const JobStats& stats) const;

  std::filesystem::path manifest_path() const;
  std::filesystem::path stats_path() const;

 private:
  SliceJobParams params_;
  bool existed_ = false, was_empty_ = false, kept_ = false;
  std::optional<JobFolderLock> lock_;
  std::optional<ConstructionCache> cache_;
};

}  // namespace trivox
