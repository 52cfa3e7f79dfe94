// What a job hands its output writers (layer_writer.h) besides the context of job_parts.h
// (made here too): the colour-to-material sheet and the extra members of a GrabCAD package.
// Shared by the job and its estimate, so that both make the same writers.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "trivox/job/job.h"
#include "trivox/output/detail/material_sheet.h"
#include "trivox/output/layer_writer.h"

namespace trivox::detail {

// The rows of materials.csv: each material with its library match and its image colour.
std::vector<MaterialSheetRow> job_material_sheet(const Scene& scene);

// A binary STL of the boundary of every cell's volume (trims not applied), in model
// space (mm): each of the six faces of each volume sampled on a 32 x 32 grid of its
// parameters, two triangles per grid cell, facing outwards.
std::string cells_boundary_stl(const Scene& scene);

// The writers of the job's formats (not of --preview's layers). In a shard
// (JobParams::shard_count > 1) of a job with stack outputs (is_stack_format) these give way to one stack-parts writer
// (output/detail/stack_parts.h): the shard keeps its layers for the stack outputs, which the whole job's resume after
// the merge writes. Their own checks of the job (a printer with a display, for one) still refuse the shard: each is
// made once in a scratch folder under the parts' folder, and dropped.
std::vector<std::unique_ptr<LayerWriter>> job_format_writers(const OutputContext& context, const JobParams& params);

}  // namespace trivox::detail
