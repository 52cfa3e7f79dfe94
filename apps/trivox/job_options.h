// The options that describe a slicing job, shared by `trivox slice` and `trivox validate` so
// that validating a command line checks exactly the job that slicing it would run; and the
// estimate report both print (docs/CLI.md, "slice", "validate").
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trivox/job/job.h"
#include "trivox/job/job_estimate.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slice_params.h"

namespace CLI {
class App;
}

namespace trivox::cli {

struct JobOptions {
  std::string scene;
  std::string output;
  int threads = 0;
  std::string layers;
  std::string tracing = std::string(to_string(SliceParams{}.tracing));
  double residual_tolerance_mm = SliceParams{}.newton.residual_tolerance_model;
  std::optional<double> outline_tolerance_mm;  // absent: the slicer's default
  std::string dither;                          // empty: the scene's method
  std::optional<int> skin_voxels;              // unset: the scene's
  std::optional<bool> vary_by_layer;           // unset: the scene's
  std::vector<std::string> formats{"voxelprint"};
  std::string prefix = "slice_";
  std::vector<int> background;  // empty: automatic (JobParams::background_rgba)
  std::string gcvf_names = "codes";
  bool gcvf_all_materials = false;
  std::vector<std::string> gcvf_extras;
  std::optional<int> min_layers;    // nullopt: as the formats need (min_layers_of)
  std::vector<int> preview_layers;  // 1-based
  std::string shard;
  double memory_limit_mb = 0;  // 0 = the machine's memory (memory_limit_bytes())
  bool no_checks = false;
  bool allow_empty = false;  // a stack without the object is not an error
};

// Adds the scene argument and every job option; `output_required` for slice.
void add_job_options(CLI::App& cmd, JobOptions& o, bool output_required);

// The parameters the options describe for `scene` (the dithering starts from the scene's
// settings); throws UsageError for values CLI11 cannot check.
SliceParams slice_params_of(const JobOptions& o, const Scene& scene);
JobParams job_params_of(const JobOptions& o);

// Prints "trivox: warning: ..." on standard error for a printer profile whose layer
// thickness no print mode of its family prints (printer_profile.h).
void warn_about_printer(const Scene& scene);

// The memory limit the checks use, in bytes.
std::optional<std::uint64_t> memory_limit_of(const JobOptions& o);

// Estimate lines for a person, each "  name: value".
void print_estimate(const JobEstimate& e);

// One line per material whose colour is nearly the previews' `background`
// (job_preview_background) and per pair of materials whose colours are nearly equal
// (output/display_colours.h), saying how previews show them; empty when every colour is
// distinct.
std::vector<std::string> colour_warnings(const Scene& scene, const std::array<std::uint8_t, 4>& background);

}  // namespace trivox::cli
