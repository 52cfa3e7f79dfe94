// Greyscale layers (Scene::greyscale): the grey of every pixel from the slicer's material
// grid, and anti-aliased edges from the exact geometry.
//
// Edges: a pixel crossed by an outline (a cell's boundary, a trimming volume's, a trimming
// shell's) is neither wholly in nor wholly out, and exposing it fully or not at all leaves a
// staircase of one pixel. Such a pixel takes instead the mean grey of k x k sub-samples at
// the centres of a regular k x k grid over its square, each decided like a pixel centre:
// the one decision of the slicer's pixels (layer_decision.h) made on the sub-sample grid:
// traced inversion of every cell's volume, the cells' trims, the owning cell (the last in
// scene order that gives material) and its material's grey. Its
// grey is then its covered fraction times its material's grey, to the accuracy of the grid:
// a straight edge through the pixel is placed within half a sub-sample, so the grey of an edge
// pixel is within 1/(2k) of full exposure, plus rounding, of the exact area (docs/SCENE.md,
// "Greyscale" gives the measured errors). Pixels away from every outline are not sampled again.
//
// The band of edge pixels: those whose square, widened by twice the outline tolerance, meets
// the outline of the layer's plane (tessellated within that tolerance of the exact surface,
// the tolerance an eighth of the sub-sample pitch).
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "layer_decision.h"
#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"

namespace trivox::detail {

// The grey layer of a sliced layer: for every pixel whose fractions sum above 0, the
// calibration curve at its scalar (the greyscale material's fraction, or `values` from
// LayerDecision::DecidedRow::grey_source, where the source is a scalar source); 0 elsewhere. Only the columns
// `written` (per row: first and last, first > last for none) can hold material.
GreyImage grey_from_grid(const MaterialGrid& grid, const std::vector<std::pair<int, int>>& written,
                         const GreyscaleDef& greyscale, std::span<const float> values);

// The decision the edge coverage makes, prepared for the points of `grid` (its sub-sample
// grid): outline meshes within an eighth of the grid's finest pitch, every trivariate traced
// once per layer. Also the entry point of the test that compares it, on the pixel grid (k =
// 1), with the slicer's.
std::unique_ptr<LayerDecision> coverage_decision(const Scene& scene, const SliceParams& params,
                                                 const SliceLayout& grid);

// The points of a decision's grid as the edge coverage decides them, numbered by the caller:
// each point's owner (claim_point) and, where its owner gave it material, the owner's
// fractions there (m per point) and its greyscale source's value (a cell with one).
struct DecidedPoints {
  std::vector<int> owner;                         // the owning cell, -1 in none
  std::vector<std::uint8_t> owner_gave_material;  // 1 where the owner gave material
  std::vector<float> fractions;                   // m per point; 0 where no cell gave material
  std::vector<float> grey_source;                 // per point; 0 where no such cell gave material
};

// Decides the points of `decision`'s grid within `only` (every point when null) at height
// z_mm into `out`: point (col, row) is number index(col, row), below `count`. The
// anti-aliasing reads its sub-samples' greys from it; a test compares it, on the pixel grid,
// with the slicer's layer.
template <class Index>
void decide_points(const LayerDecision& decision, double z_mm, const RowSpans* only, std::size_t count, int m,
                   Index index, DecidedPoints& out) {
  const auto mm = static_cast<std::size_t>(m);
  out.owner.assign(count, -1);
  out.owner_gave_material.assign(count, 0);
  out.fractions.assign(count * mm, 0.0f);
  out.grey_source.assign(count, 0.0f);
  LayerDecision::Layer state;
  decision.decide(state, z_mm, only, [&](const LayerDecision::DecidedRow& d) {
    for (std::size_t i = 0; i < d.points.cols.size(); ++i) {
      const std::size_t at = index(d.points.cols[i], d.row);
      const float* f = d.fractions.data() + i * mm;
      float sum = 0.0f;
      for (std::size_t j = 0; j < mm; ++j) sum += f[j];
      if (!claim_point(d.cell, sum > 0.0f, out.owner[at], out.owner_gave_material[at])) continue;
      std::copy(f, f + mm, out.fractions.begin() + static_cast<std::ptrdiff_t>(at * mm));
      if (!d.grey_source.empty()) out.grey_source[at] = d.grey_source[i];
    }
  });
}

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
  const Scene& scene_;
  SliceLayout layout_;  // the pixel grid
  SliceLayout fine_;    // the sub-sample grid: k times finer in x and y, the same origin
  int k_ = 2;
  double tolerance_mm_ = 0;                  // of the fine outlines
  std::unique_ptr<LayerDecision> decision_;  // on fine_
};

}  // namespace trivox::detail
