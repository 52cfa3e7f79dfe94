// A whole slicing job: every layer of a scene, in parallel, streamed to the output folder.
//
// Determinism: each layer depends only on the scene, the settings and its index, so the
// files are byte-identical for any thread count and schedule. Memory stays flat in the
// number of layers: a worker holds one layer at a time and writes it before the next.
//
// Safety: every file is written atomically (atomic_file.h), and manifest.json (manifest.h)
// records the job as layers complete, so a job that is stopped (JobParams::stop), killed or
// fails can be resumed (JobParams::resume) and ends with the same bytes as one that ran
// through. A job can also be split into shards (JobParams::shard_*), merged with
// merge_shards() (job_folder.h). SliceJob (slice_job.h) is the whole job around
// run_slice_job: the folder locked before the scene is read, the construction cache, the
// checks and the empty-result rule.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "trivox/job/manifest.h"
#include "trivox/job/printed_extent.h"
#include "trivox/output/png_io.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/slice/slicer.h"

namespace trivox {

class JobFolderLock;  // job_lock.h

// How the "gcvf" package is written where the public package writers differ
// (docs/FORMATS.md, "GrabCAD Voxel Print package").
struct GcvfJobOptions {
  bool material_codes = true;  // ConfigFile.xml names materials by their Stratasys codes where known
  bool omit_unused = true;     // materials with no voxel are left out of the list
  bool mesh_stl = false;       // add model.stl: the boundary of every cell's volume
  bool bounding_box = false;   // add bounding_box.txt: the stack's box in mm

  bool operator==(const GcvfJobOptions&) const = default;
};

struct JobParams {
  std::filesystem::path output_dir;
  // Layers first..last (inclusive, 0-based); last < 0 means the model's last layer.
  int first_layer = 0;
  int last_layer = -1;
  int threads = 0;                                 // 0 = all cores
  std::vector<std::string> formats{"voxelprint"};  // see layer_writer.h
  std::string prefix = "slice_";
  // The background colour of the printer images, opaque (alpha 255). nullopt: automatic, black
  // (0, 0, 0, 255) as in the public Voxel Print packages, unless a material is black
  // (job_background()).
  std::optional<std::array<std::uint8_t, 4>> background_rgba;
  GcvfJobOptions gcvf;
  // Shorter jobs are padded with empty (background) layers after the model's up to this many
  // layers, 0 to kMaxMinLayers. nullopt: as the formats need (min_layers_of): GrabCAD Voxel
  // Print needs kVoxelPrintMinLayers; the other printers' formats (SL1, SL1S, greyscale PNGs)
  // and the generic ones (TIFF, OpenVDB) are not padded.
  std::optional<int> min_layers;
  static constexpr int kVoxelPrintMinLayers = 30;
  static constexpr int kMaxMinLayers = 1000;
  PngWriteParams png;
  // Model layers (0-based, within first..last) also written for a person to look at:
  // preview/layer_NNNNN.png, NNNNN the 1-based layer number, in opaque display colours with
  // square pixels (output/layer_preview_writer.cpp).
  std::vector<int> preview_layers;

  // Continue the job recorded in the folder's manifest: layers whose files are listed there
  // and still match their size and SHA-256 are kept; the rest are sliced. Refused (Error) when
  // the manifest's tool version, inputs or settings differ from this job's. Without a
  // manifest the job starts from scratch.
  bool resume = false;
  // Shard `shard_index` (1-based) of `shard_count`: only the job layers shard_has_layer()
  // deals to it, recorded in manifest.shard-I-of-N.json and stats.shard-I-of-N.json.
  int shard_index = 1;
  int shard_count = 1;
  // Checked before each layer: once true, no new layer starts, layers in progress finish,
  // and the manifest is marked interrupted. May be set from a signal handler.
  const std::atomic<bool>* stop = nullptr;
  // How often (seconds) the manifest is rewritten while layers complete; 0 = after every
  // layer. A layer finished but not yet recorded is simply sliced again on resume.
  double manifest_interval_seconds = 1.0;
  // The lock of the output folder (job_lock.h) when the caller took it before the job, e.g.
  // to refuse a second job before reading the scene; it must be for output_dir and this
  // shard. nullptr: run_slice_job takes the lock itself, and releases it when it returns.
  JobFolderLock* folder_lock = nullptr;
  // The memory the job may use, in bytes; nullopt: no limit. The one place the limit enters:
  // the estimate (estimate_job, which then slices no sample layer of a job already over it),
  // check_job_fits, and the slicer's outlines through SliceJob::slice_params().
  std::optional<std::uint64_t> memory_limit_bytes;
};

// The layers a job's stack is padded to: JobParams::min_layers when given, else
// kVoxelPrintMinLayers when one of its formats feeds GrabCAD Voxel Print
// (layer_writer_feeds_voxel_print), else 0.
int min_layers_of(const JobParams& params);

struct JobStats {
  SliceLayout layout;
  std::vector<LayerStats> layers;       // in layer order
  LayerStats total;                     // the layers summed (sum_layer_stats), as stats.json's "total"
  int padded_layers = 0;                // empty layers added to reach min_layers
  int first_layer = 0, last_layer = 0;  // the model's layers the job covers (0-based, inclusive)
  double seconds = 0;                   // wall time of the whole job
  int threads = 0;
  std::vector<std::string> files;  // every file written by this run, relative to the output folder, sorted
  int layers_kept = 0;             // job layers a resumed job found complete and did not redo
  bool interrupted = false;        // JobParams::stop ended the job early (manifest: interrupted)
  PrintedExtent printed;           // the voxels with a material, of the whole job: the layers this run
                                   // sliced and those a resumed job kept (ManifestPrinted)
};

// Reports progress from the job's workers (calls are serialised by the job).
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void on_layer_done(int done, int total) = 0;
};

// What --resume does for the outputs written only when a job completes (the stack formats,
// is_stack_format): they keep no finished layer, so a resumed
// job slices its kept layers once more for them, and every layer when they are all it writes
// (unless the layers come from shards, which keep them as stack parts for the merged job's
// resume: output/detail/stack_parts.h). One sentence for the interruption's message and the
// manifest; empty when the job has none, and for a shard.
std::string stack_resume_note(const JobParams& params);

// Slices and writes the layers, keeping the manifest up to date, then the colour-to-material
// sheet materials.csv (output/detail/material_sheet.h); writes stats.json last
// (stats.shard-I-of-N.json for a shard). Throws trivox::Error for settings the printer cannot
// take (more materials than its colour limit), for a refused resume and for a folder another
// job is writing into (JobParams::folder_lock, job_lock.h), IoError when the
// folder or a file cannot be written (the manifest is then marked failed, when it can be).
// Returns with stats.interrupted set when JobParams::stop was raised.
JobStats run_slice_job(const Slicer& slicer, const JobParams& params, ProgressSink* progress = nullptr);

// Throws Error when the job cannot run on the scene's printer or with these settings: more
// materials than the printer takes, a shard number out of range, an empty layer range.
void check_job_settings(const Slicer& slicer, const JobParams& params);

// The background the job's printer images use: JobParams::background_rgba, or automatically
// the first of black, white and the greys (n, n, n) from n = 1 up that no material's opaque
// colour takes.
std::array<std::uint8_t, 4> job_background(const Scene& scene, const JobParams& params);
// The background of the job's previews (layer previews, contact sheets, cuts): the one given
// (JobParams::background_rgba), else chosen by contrast with every material
// (preview_background, output/display_colours.h), so that a dark material is not lost on the
// printer images' black.
std::array<std::uint8_t, 4> job_preview_background(const Scene& scene, const JobParams& params);

// The manifest this job starts from: tool version, inputs, effective settings and layer
// count, status running, no files.
JobManifest job_manifest(const Slicer& slicer, const JobParams& params);

// The construction cache of a job's output folder (scene/construction_cache.h), which
// SliceJob (slice_job.h) reads the scene through: DIR/.trivox-cache. Repeated runs into the folder,
// --resume and every shard of the job then build each constructed volume once.
inline std::filesystem::path construction_cache_dir(const std::filesystem::path& output_dir) {
  return output_dir / kConstructionCacheFolder;
}

// stats.json (FORMATS.md): the job's settings, then per layer and in total the columns of
// the paper's Table 2 and how the pixels were settled (stats_json.cpp).
void write_stats_json(const std::filesystem::path& path, const Slicer& slicer, const JobStats& stats);

}  // namespace trivox
