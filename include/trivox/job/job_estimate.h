// What a job will cost before it starts: layers, pixels, output size, peak memory and time,
// from the layout and from slicing and encoding a few sample layers; and the up-front checks
// that refuse a job the disk or the memory limit cannot take (docs/CLI.md, "validate").
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "trivox/job/job.h"

namespace trivox {

struct EstimateParams {
  // Model layers sliced and encoded to measure file size and time, spread evenly over the
  // job's range (fewer when the range is shorter). 0 = size and time are not estimated.
  // When the estimate of the job's memory without samples already exceeds the job's memory
  // limit (JobParams::memory_limit_bytes), no sample layer is sliced (sampled_layers is then
  // 0), so that check_job_fits refuses a job too large for memory before any of its layers is
  // built.
  int sample_layers = 3;
};

struct JobEstimate {
  int model_layers = 0;   // layers of the job's range
  int padded_layers = 0;  // empty layers added for min_layers
  int job_layers = 0;     // model + padded, divided among shards
  int width_px = 0, height_px = 0;
  std::int64_t pixels = 0;               // voxels of every job layer of this shard
  int files_per_layer = 0;               // from the formats
  int whole_job_files = 0;               // files of the whole job: materials.csv and the stack outputs
  int sampled_layers = 0;                // 0 when output size and time are not measured
  std::uint64_t output_bytes = 0;        // layer files + whole-job files + stats.json + manifest; from the samples
  std::uint64_t stats_bytes = 0;         // of which stats.json: an entry per model layer
  std::uint64_t scratch_bytes = 0;       // spool files of the stack outputs, on disk until the job ends
  std::uint64_t peak_memory_bytes = 0;   // process now + per worker buffers x threads + stack outputs
  std::uint64_t stack_memory_bytes = 0;  // the stack outputs' part of the peak (e.g. OpenVDB grids)
  double seconds = 0;                    // sample time per layer x layers / threads
  int threads = 0;
};

// Estimates the job `params` describes (its shard, its thread count). Slices the sample
// layers into a scratch folder under the system's temporary directory, removed afterwards.
JobEstimate estimate_job(const Slicer& slicer, const JobParams& params, const EstimateParams& estimate = {});

// Free bytes for an unprivileged user on the file system that holds `dir` (or its nearest
// existing parent); nullopt when statvfs fails.
std::optional<std::uint64_t> free_disk_bytes(const std::filesystem::path& dir);

// Throws Error naming the folder, the estimate and the limit when the output and the spool
// files exceed the free space of `params.output_dir` or the peak memory exceeds
// `params.memory_limit_bytes` (nullopt = no memory check).
void check_job_fits(const JobEstimate& estimate, const JobParams& params);
// The same against `free_disk` bytes (nullopt = no disk check) instead of a measurement.
void check_job_fits(const JobEstimate& estimate, const JobParams& params, std::optional<std::uint64_t> free_disk);

// "1.23 GB", "456 MB", "12.3 kB", "17 B" (decimal units).
std::string byte_text(std::uint64_t bytes);

// "1 thread", "2 threads".
std::string thread_text(int threads);

}  // namespace trivox
