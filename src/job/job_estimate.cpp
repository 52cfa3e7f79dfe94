#include "trivox/job/job_estimate.h"

#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "job_outputs.h"
#include "job_parts.h"
#include "trivox/error.h"
#include "trivox/output/detail/material_sheet.h"
#include "trivox/output/layer_writer.h"
#include "trivox/parallel.h"

namespace trivox {

namespace {

// Resident memory of this process now (scene, models, prepared cells); 0 when unknown.
std::uint64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t size = 0, resident = 0;
  if (!(statm >> size >> resident)) return 0;
  return resident * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

// What one worker holds while it slices and writes a layer: the material fractions (float
// per material per pixel), the inside mask and the labels (a byte per pixel each), the
// dithering's working copy of the fractions, and the largest encoder buffer (RGBA: 4 bytes
// per pixel); the tracing's own share comes from Slicer::tracing_bytes_per_worker.
std::uint64_t worker_bytes(std::uint64_t pixels, int materials) {
  return pixels * (2u * 4u * static_cast<std::uint64_t>(materials) + 1u + 1u + 4u);
}

// Bytes of the manifest's line for one file (name, size and a 64-digit hash).
constexpr std::uint64_t kManifestBytesPerFile = 140;

// stats.json as the job will write it: one entry per model layer of this shard (its figures
// those of a sample layer, in turn), written by the job's own writer and measured. Its size
// grows with the layers, the materials and the cells (a few hundred bytes a layer), which on
// a tall job of small layers is a good part of the output.
std::uint64_t stats_json_bytes(const Slicer& slicer, const JobEstimate& e, int first, int shard_model,
                               const JobParams& params, const std::vector<LayerStats>& samples,
                               const std::filesystem::path& scratch) {
  JobStats stats;
  stats.layout = slicer.layout();
  stats.padded_layers = e.padded_layers;
  stats.threads = e.threads;
  stats.seconds = 1.0;
  std::size_t next = 0;
  for (int index = 0; index < e.model_layers && static_cast<int>(stats.layers.size()) < shard_model; ++index) {
    if (!shard_has_layer(index, params.shard_index, params.shard_count)) continue;
    LayerStats s = samples[next++ % samples.size()];
    s.layer = first + index;
    s.z_mm = slicer.layout().z_of_layer(first + index);
    stats.layers.push_back(std::move(s));
  }
  stats.total = sum_layer_stats(stats.layers, static_cast<std::size_t>(slicer.scene().num_materials()),
                                slicer.scene().cells.size());
  const std::filesystem::path path = scratch / stats_file_name(1, 1);
  write_stats_json(path, slicer, stats);
  return std::filesystem::file_size(path);
}

}  // namespace

namespace {

// `message` with the estimate's scratch folder named as the output folder whose files the
// samples stand for (the scratch folder's name is no path a user knows), and where the
// samples were written, so that a failure is still traced to its place.
std::string without_scratch(std::string message, const std::filesystem::path& scratch,
                            const std::filesystem::path& output_dir) {
  const std::string from = scratch.string();
  if (from.empty() || message.find(from) == std::string::npos) return message;
  for (std::size_t at = message.find(from); at != std::string::npos; at = message.find(from, at))
    message.replace(at, from.size(), output_dir.string()), at += output_dir.string().size();
  return fmt::format("{} (while the estimate wrote its sample layers under {})", message,
                     scratch.parent_path().string());
}

JobEstimate estimate_job_in(const Slicer& slicer, const JobParams& params, const EstimateParams& ep,
                            std::filesystem::path& scratch_out);

}  // namespace

JobEstimate estimate_job(const Slicer& slicer, const JobParams& params, const EstimateParams& ep) {
  std::filesystem::path scratch;
  try {
    return estimate_job_in(slicer, params, ep, scratch);
  } catch (const IoError& e) {
    throw IoError(without_scratch(e.what(), scratch, params.output_dir));
  } catch (const CancelledError&) {
    throw;
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    if (without_scratch(e.what(), scratch, params.output_dir) == e.what()) throw;
    throw Error(without_scratch(e.what(), scratch, params.output_dir));
  }
}

namespace {

JobEstimate estimate_job_in(const Slicer& slicer, const JobParams& params, const EstimateParams& ep,
                            std::filesystem::path& scratch_out) {
  const SliceLayout& L = slicer.layout();
  check_job_settings(slicer, params);
  const JobManifest m = job_manifest(slicer, params);
  const detail::LayerRange range = detail::layer_range(L, params);
  const int first = range.first;
  JobEstimate e;
  e.model_layers = range.count;
  e.padded_layers = m.total_layers - e.model_layers;
  int shard_model = 0, shard_padded = 0;
  for (int index = 0; index < m.total_layers; ++index)
    if (shard_has_layer(index, params.shard_index, params.shard_count))
      (index < e.model_layers ? shard_model : shard_padded)++;
  e.job_layers = shard_model + shard_padded;
  e.width_px = L.width_px;
  e.height_px = L.height_px;
  const auto layer_pixels = static_cast<std::uint64_t>(L.width_px) * static_cast<std::uint64_t>(L.height_px);
  e.pixels = static_cast<std::int64_t>(layer_pixels * static_cast<std::uint64_t>(e.job_layers));
  e.threads = worker_count(params.threads);
  e.peak_memory_bytes = resident_bytes() + static_cast<std::uint64_t>(std::min(e.threads, std::max(1, e.job_layers))) *
                                               (worker_bytes(layer_pixels, slicer.scene().num_materials()) +
                                                slicer.tracing_bytes_per_worker());

  const int samples = std::min(ep.sample_layers, e.model_layers);
  if (samples <= 0) return e;
  if (params.memory_limit_bytes.value_or(0) > 0 && e.peak_memory_bytes > *params.memory_limit_bytes) return e;
  static std::atomic<int> counter{0};
  const std::filesystem::path scratch = std::filesystem::temp_directory_path() /
                                        fmt::format("trivox-estimate-{}-{}", static_cast<long>(::getpid()), counter++);
  scratch_out = scratch;
  struct Cleanup {
    std::filesystem::path dir;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  } cleanup{scratch};
  std::error_code ec;
  std::filesystem::create_directories(scratch, ec);
  if (ec)
    throw IoError(fmt::format("{}: cannot create a scratch folder for the estimate there: {}",
                              scratch.parent_path().string(), ec.message()));
  const OutputContext ctx = detail::job_output_context(slicer, params, scratch);
  const std::vector<std::unique_ptr<LayerWriter>> writers = detail::job_format_writers(ctx, params);

  auto encode = [&](int index, const LayerResult& layer) {
    std::uint64_t bytes = 0;
    int files = 0;
    for (const auto& w : writers)
      for (const std::string& name : write_layer_to(*w, index, layer.labels, layer.grey)) {
        bytes += std::filesystem::file_size(scratch / name);
        ++files;
      }
    e.files_per_layer = files;
    return bytes;
  };
  std::uint64_t sample_bytes = 0;
  StackSampling sampling;
  sampling.model_layers = shard_model;
  sampling.padded_layers = shard_padded;
  std::vector<LayerStats> sample_stats;
  const auto start = std::chrono::steady_clock::now();
  for (int s = 0; s < samples; ++s) {
    // Evenly spread: the middle of each of `samples` equal parts of the range.
    const int index = static_cast<int>((2 * s + 1) * static_cast<std::int64_t>(e.model_layers) / (2 * samples));
    LayerResult r = slicer.slice_layer(first + index);
    sample_bytes += encode(index, r);
    sample_stats.push_back(std::move(r.stats));
    sampling.model_samples.push_back(index);
  }
  const double per_layer = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / samples;
  std::uint64_t padding_bytes = 0;
  if (shard_padded > 0) {
    LayerResult padding;
    padding.labels = LabelImage(L.width_px, L.height_px, LabelImage::kVoid);
    padding_bytes = encode(e.model_layers, padding);
    sampling.padding_sample = e.model_layers;
  }
  // The whole-job files: the colour-to-material sheet, measured, and what the stack outputs
  // will write, hold on disk while the job runs and keep in memory, from the same samples.
  write_material_sheet(scratch / "materials.csv", ctx.background_rgba, detail::job_material_sheet(slicer.scene()));
  std::uint64_t whole_job_bytes = std::filesystem::file_size(scratch / "materials.csv");
  e.whole_job_files = 1;
  for (const auto& w : writers) {
    const StackCost cost = w->stack_cost(sampling);
    e.whole_job_files += cost.files;
    whole_job_bytes += cost.file_bytes;
    e.scratch_bytes += cost.scratch_bytes;
    e.stack_memory_bytes += cost.memory_bytes;
  }
  e.peak_memory_bytes += e.stack_memory_bytes;
  e.stats_bytes = stats_json_bytes(slicer, e, first, shard_model, params, sample_stats, scratch);
  e.sampled_layers = samples;
  const std::uint64_t files = static_cast<std::uint64_t>(e.files_per_layer) * static_cast<std::uint64_t>(e.job_layers) +
                              static_cast<std::uint64_t>(e.whole_job_files);
  e.output_bytes = sample_bytes / static_cast<std::uint64_t>(samples) * static_cast<std::uint64_t>(shard_model) +
                   padding_bytes * static_cast<std::uint64_t>(shard_padded) + whole_job_bytes + e.stats_bytes +
                   kManifestBytesPerFile * files;
  e.seconds = per_layer * std::ceil(static_cast<double>(shard_model) / e.threads);
  return e;
}

}  // namespace

std::optional<std::uint64_t> free_disk_bytes(const std::filesystem::path& dir) {
  std::filesystem::path p = dir.empty() ? std::filesystem::path(".") : dir;
  std::error_code ec;
  while (!std::filesystem::exists(p, ec)) {
    if (p.has_parent_path() && p.parent_path() != p) {
      p = p.parent_path();
    } else {  // a relative path none of whose folders exists yet: it will be made here
      p = p.is_absolute() ? p.root_path() : std::filesystem::path(".");
      break;
    }
  }
  struct statvfs st {};
  if (::statvfs(p.c_str(), &st) != 0) return std::nullopt;
  return static_cast<std::uint64_t>(st.f_bavail) * static_cast<std::uint64_t>(st.f_frsize);
}

void check_job_fits(const JobEstimate& e, const JobParams& params) {
  check_job_fits(e, params, e.sampled_layers > 0 ? free_disk_bytes(params.output_dir) : std::nullopt);
}

void check_job_fits(const JobEstimate& e, const JobParams& params, std::optional<std::uint64_t> free_disk) {
  const std::optional<std::uint64_t>& memory_limit = params.memory_limit_bytes;
  if (e.sampled_layers > 0 && free_disk) {
    const std::uint64_t needed = e.output_bytes + e.scratch_bytes;
    if (needed > *free_disk) {
      std::string what = fmt::format("{} layers x {} files", e.job_layers, e.files_per_layer);
      if (e.whole_job_files > 0) what += fmt::format(", {} files of the whole job", e.whole_job_files);
      if (e.scratch_bytes > 0) what += fmt::format(", {} of spool files while it runs", byte_text(e.scratch_bytes));
      throw Error(
          fmt::format("{}: the job needs about {} of disk ({}) but only {} is free there; "
                      "free some space, choose another folder, or override with --no-checks",
                      params.output_dir.string(), byte_text(needed), what, byte_text(*free_disk)));
    }
  }
  if (memory_limit && e.peak_memory_bytes > *memory_limit)
    throw Error(fmt::format(
        "the job needs about {} of memory with {} ({} x {} px layers{}) but the limit is {}; "
        "use fewer threads (-j), raise --memory-limit, or override with --no-checks",
        byte_text(e.peak_memory_bytes), thread_text(e.threads), e.width_px, e.height_px,
        e.stack_memory_bytes > 0 ? fmt::format(", {} of it for the stack outputs", byte_text(e.stack_memory_bytes))
                                 : std::string(),
        byte_text(*memory_limit)));
}

std::string byte_text(std::uint64_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b >= 1e9) return fmt::format("{:.2f} GB", b / 1e9);
  if (b >= 1e6) return fmt::format("{:.1f} MB", b / 1e6);
  if (b >= 1e3) return fmt::format("{:.1f} kB", b / 1e3);
  return fmt::format("{} B", bytes);
}

std::string thread_text(int threads) { return fmt::format("{} thread{}", threads, threads == 1 ? "" : "s"); }

}  // namespace trivox
