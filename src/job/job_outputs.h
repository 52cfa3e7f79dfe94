// What a job hands its output writers (layer_writer.h) besides the context of job_parts.h
// (made here too): the colour-to-material sheet and the extra members of a GrabCAD package.
// Shared by the job and its estimate, so that both make the same writers.
#pragma once

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

}  // namespace trivox::detail
