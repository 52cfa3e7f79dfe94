// A whole slicing job: every layer of a scene, in parallel, streamed to the output folder.
//
// Determinism: each layer depends only on the scene, the settings and its index, so the
// files are byte-identical for any thread count and schedule. Memory stays flat in the
// number of layers: a worker holds one layer at a time and writes it before the next.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/output/png_io.h"
#include "trivox/slice/slicer.h"

namespace trivox {

struct JobParams {
  std::filesystem::path output_dir;
  // Layers first..last (inclusive, 0-based); last < 0 means the model's last layer.
  int first_layer = 0;
  int last_layer = -1;
  int threads = 0;  // 0 = all cores
  std::vector<std::string> formats{"voxelprint"};  // see layer_writer.h
  std::string prefix = "slice_";
  std::array<std::uint8_t, 4> background_rgba{255, 255, 255, 255};
  // GrabCAD Voxel Print needs at least this many layers; shorter jobs are padded with empty
  // (background) layers after the model's.
  int min_layers = 30;
  PngWriteParams png;
};

struct JobStats {
  SliceLayout layout;
  std::vector<LayerStats> layers;  // in layer order
  int padded_layers = 0;           // empty layers added to reach min_layers
  double seconds = 0;              // wall time of the whole job
  int threads = 0;
  std::vector<std::string> files;  // every file written, relative to the output folder, sorted
};

// Reports progress from the job's workers (calls are serialised by the job).
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void on_layer_done(int done, int total) = 0;
};

// Slices and writes the layers, then the colour-to-material sheet materials.csv
// (output/material_sheet.h); writes stats.json last. Throws trivox::Error for settings the
// printer cannot take (more materials than its colour limit), IoError when the folder or a
// file cannot be written.
JobStats run_slice_job(const Slicer& slicer, const JobParams& params, ProgressSink* progress = nullptr);

// stats.json: per layer and in total, the columns of the paper's Table 2.
void write_stats_json(const std::filesystem::path& path, const Slicer& slicer, const JobStats& stats);

}  // namespace trivox
