// Greyscale layers (Scene::greyscale): the grey of every pixel from the slicer's material
// grid, and anti-aliased edges from the exact geometry.
//
// Edges: a pixel crossed by an outline (a cell's boundary, a trimming volume's, a trimming
// shell's) is neither wholly in nor wholly out, and exposing it fully or not at all leaves a
// staircase of one pixel. Such a pixel takes instead the mean grey of k x k sub-samples at
// the centres of a regular k x k grid over its square, each decided like a pixel centre:
// traced inversion of every cell's volume on the sub-sample grid, the cells' trims, the
// owning cell (the last in scene order that gives material) and its material's grey. Its
// grey is then its covered fraction times its material's grey, to the accuracy of the grid:
// a straight edge through the pixel is placed within half a sub-sample, so the grey of an edge
// pixel is within 1/(2k) of full exposure, plus rounding, of the exact area (docs/SCENE.md,
// "Greyscale" gives the measured errors). Pixels away from every outline are not sampled again.
//
// The band of edge pixels: those whose square, widened by twice the outline tolerance, meets
// the outline of the layer's plane (tessellated within that tolerance of the exact surface,
// the tolerance an eighth of the sub-sample pitch).
#pragma once

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "cell_tracer.h"
#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"

namespace trivox::detail {

// The scalar of the greyscale source where a cell gives material, for one traced row: for
// each sample k whose fractions (m per sample, sample-major) sum above 0, values[row *
// width + cols[k]] = the cell's grey source there. `scratch` is reused between calls.
void grey_source_row(const MaterialFunction& source, const TracedRow& row, std::span<const float> fractions, int m,
                     int r, int width_px, std::span<float> values, std::vector<float>& scratch);

// The grey layer of a sliced layer: for every pixel whose fractions sum above 0, the
// calibration curve at its scalar (the greyscale material's fraction, or `values` from
// grey_source_row when the source is a scalar source); 0 elsewhere. Only the columns
// `written` (per row: first and last, first > last for none) can hold material.
GreyImage grey_from_grid(const MaterialGrid& grid, const std::vector<std::pair<int, int>>& written,
                         const GreyscaleDef& greyscale, std::span<const float> values);

class EdgeCoverage {
 public:
  // Prepares every trivariate and trimming shell of the scene's cells for sub-sampling on a
  // grid k times finer than `layout` (k = greyscale.antialiasing, at least 2).
  EdgeCoverage(const Scene& scene, const SliceParams& params, const SliceLayout& layout);
  ~EdgeCoverage();
  EdgeCoverage(const EdgeCoverage&) = delete;
  EdgeCoverage& operator=(const EdgeCoverage&) = delete;

  // Replaces the grey of every edge pixel of layer `layer` with the mean grey of its k x k
  // sub-samples. Returns the number of edge pixels. Safe to call from several threads.
  std::int64_t antialias(int layer, GreyImage& grey) const;

  int factor() const noexcept { return k_; }

 private:
  struct Trivariate;
  struct CellData;
  const Scene& scene_;
  const SliceParams& params_;
  SliceLayout layout_;  // the pixel grid
  SliceLayout fine_;    // the sub-sample grid: k times finer in x and y, the same origin
  int k_ = 2;
  double tolerance_mm_ = 0;  // of the fine outlines
  std::vector<std::unique_ptr<Trivariate>> trivariates_;
  std::vector<std::unique_ptr<CellData>> cells_;
  int shell_slots_ = 0;
};

}  // namespace trivox::detail
