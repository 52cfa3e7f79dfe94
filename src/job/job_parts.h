// What the slice job (job.cpp) and its estimate (job_estimate.cpp) both derive from the
// job's settings: the layer range and the output writers' context. Private to the slice
// layer.
#pragma once

#include <filesystem>

#include "trivox/job/job.h"
#include "trivox/output/layer_writer.h"

namespace trivox::detail {

struct LayerRange {
  int first = 0, last = 0, count = 0;  // model layers first..last
  int padded = 0;                      // empty layers after them
  int total() const noexcept { return count + padded; }
};

// The model layers JobParams selects and the padding up to min_layers; throws Error when
// the range selects no layer.
LayerRange layer_range(const SliceLayout& layout, const JobParams& params);

// The writers' context for this job writing into `dir` (the output folder, or the
// estimate's scratch folder).
OutputContext job_output_context(const Slicer& slicer, const JobParams& params, const std::filesystem::path& dir);

}  // namespace trivox::detail
