// The printed extent of a job: the box of the voxels that receive a material, in pixels and
// layers, and in millimetres as the printer will build it (whole voxels), beside the model's
// own box. A 40 x 10 x 5 mm bar prints at 600 x 300 dpi and 30 um layers as 39.96 x 10.08 x
// 5.01 mm or so: every size a whole number of voxels, its pixel centres inside the model.
#pragma once

#include <climits>

#include "trivox/job/manifest.h"
#include "trivox/math.h"
#include "trivox/raster/material_grid.h"
#include "trivox/slice/layout.h"

namespace trivox {

struct PrintedExtent {
  // Inclusive bounds of the voxels with a material (label != void); empty when lo > hi.
  int col_lo = INT_MAX, col_hi = -1;
  int row_lo = INT_MAX, row_hi = -1;
  int layer_lo = INT_MAX, layer_hi = -1;  // layout layers (0-based)

  bool empty() const noexcept { return col_lo > col_hi; }
  void add(const PrintedExtent& other) noexcept;
};

// The voxels of one layer's labels that hold a material, as layer `layer` of the layout.
PrintedExtent printed_extent(const LabelImage& labels, int layer);
// The extent a manifest records for a layer (ManifestPrinted), as layer `layer` of the layout.
PrintedExtent printed_extent(const ManifestPrinted& recorded, int layer);

// The box those voxels fill in model space (mm): whole voxels, from the left edge of the
// first column to the right edge of the last, and so on. An empty box for an empty extent.
Box3 printed_box_mm(const PrintedExtent& extent, const SliceLayout& layout);

}  // namespace trivox
