// What a job hands its output writers (layer_writer.h): the output context, the
// colour-to-material sheet, and the extra members of a GrabCAD package. Shared by the job
// and its estimate, so that both make the same writers.
#pragma once

#include <string>
#include <vector>

#include "trivox/output/layer_writer.h"
#include "trivox/output/material_sheet.h"
#include "trivox/slice/job.h"

namespace trivox::detail {

// The context of the job's writers: the scene's materials and printer (with the greyscale
// block's exposure), the resolved background, the bitmap and its placement. `total_layers`
// and `model_layers` count the job's layers (padding included, and without); `first_layer`
// is the model layer of job layer 0.
OutputContext job_output_context(const Slicer& slicer, const JobParams& params, const std::filesystem::path& dir,
                                 int total_layers, int model_layers, int first_layer);

// The rows of materials.csv: each material with its library match and its image colour.
std::vector<MaterialSheetRow> job_material_sheet(const Scene& scene);

// A binary STL of the boundary of every cell's volume (trims not applied), in model
// space (mm): each of the six faces of each volume sampled on a 32 x 32 grid of its
// parameters, two triangles per grid cell, facing outwards.
std::string cells_boundary_stl(const Scene& scene);

}  // namespace trivox::detail
