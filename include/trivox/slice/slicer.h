// Slicing one layer of a scene: outline, inverse per pixel, material, dithering (Algorithm 1).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "trivox/raster/material_grid.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"

namespace trivox {

// The columns of the paper's Table 2, per layer.
struct LayerStats {
  int layer = 0;
  double z_mm = 0;
  double seconds = 0;                  // wall time of this layer (not part of the output bytes)
  double seconds_inverse = 0;          // of which outlines and inversion
  double seconds_material = 0;         // material evaluation
  double seconds_dither = 0;           // dithering
  std::int64_t pixels_total = 0;       // pixels in the bitmap
  std::int64_t pixels_inside = 0;      // pixels inside some cell
  std::int64_t candidates = 0;         // pixels inverted (inside the widened outlines)
  std::int64_t global_calls = 0;       // global solves
  std::int64_t global_unseeded = 0;    // of which for a pixel no solved neighbour could seed
  std::int64_t newton_evals = 0;       // evaluations of V (with or without J) by tracing and Newton
  std::int64_t guesses = 0;            // row guesses checked by one value (SLICING.md, tracing)
  std::int64_t guess_misses = 0;       // of which missed the residual tolerance
  std::int64_t jacobian_steps = 0;     // pixels evaluated with their Jacobian in a batch
  std::int64_t slow_path_pixels = 0;   // pixels settled by Newton from each neighbour, then the global solver
  std::int64_t folded_pixels = 0;      // pixels where a cell folds (several preimages)
  std::int64_t unresolved_pixels = 0;  // pixels where the global solver ran out of budget
  std::vector<std::int64_t> voxels_per_material;  // after dithering; index = scene material
  // Pixels each cell owns (index = scene cell): every inside pixel has exactly one owner,
  // so these add up to pixels_inside.
  std::vector<std::int64_t> pixels_per_cell;
};

struct LayerResult {
  LabelImage labels;  // 0 = void / background, 1 + j = scene material j
  LayerStats stats;
};

// A layer as the dithering received it, for callers that look at the material field itself
// (the Python API's slice_layer(..., fractions=True)): the fractions the owning cells' materials
// gave every pixel (all 0 outside the cells) and the inside mask.
struct LayerRasters {
  MaterialGrid fractions;
  InsideMask inside;
};

class Slicer {
 public:
  // Prepares every cell (boundary mesh, global solver) and the layout. `scene` must outlive
  // the slicer. Throws trivox::Error for invalid parameters.
  Slicer(const Scene& scene, SliceParams params);
  ~Slicer();
  Slicer(const Slicer&) = delete;
  Slicer& operator=(const Slicer&) = delete;

  const SliceLayout& layout() const noexcept { return layout_; }
  const SliceParams& params() const noexcept { return params_; }
  const Scene& scene() const noexcept { return scene_; }
  // The dithering in effect: params().dither, else the scene's, else the defaults.
  const DitherParams& dither_params() const noexcept { return dither_; }

  // Slices layer `layer` (0 .. layout().num_layers - 1). Safe to call from several threads
  // at once; the result depends only on the scene, the parameters and `layer`.
  LayerResult slice_layer(int layer) const;
  // The same, and the owner of every pixel (row-major, width_px x height_px): the index of
  // the scene cell the pixel belongs to, or -1 outside every cell. Where cells overlap (shared
  // faces of a multi-patch model), the owner is the last cell in scene order that gives the
  // pixel a non-empty material, else the last that contains it; its material is the pixel's.
  LayerResult slice_layer(int layer, std::vector<int>* owner) const;
  // The same, and when `rasters` is given a copy of the layer before dithering: dither() of
  // its fractions and mask with dither_params() and `layer` gives the result's labels.
  LayerResult slice_layer(int layer, std::vector<int>* owner, LayerRasters* rasters) const;

 private:
  struct Trivariate;
  struct CellData;
  struct LayerBuffers;
  std::unique_ptr<LayerBuffers> take_buffers() const;
  void give_back(std::unique_ptr<LayerBuffers> buffers) const;
  const Scene& scene_;
  SliceParams params_;
  DitherParams dither_;
  double outline_tolerance_mm_ = 0;
  SliceLayout layout_;
  // Every trivariate a cell uses, once: the scene's named volumes that are used (as a
  // parametrization or a trim), then each other cell's own volume.
  std::vector<std::unique_ptr<Trivariate>> trivariates_;
  std::vector<std::unique_ptr<CellData>> cells_;
  // The layers' material grids and inside masks, reused by the layers that follow: at
  // printer resolution they are tens of megabytes, and fresh ones cost every layer the
  // faulting-in and clearing of their pages. One per concurrent slice_layer call at most.
  mutable std::mutex buffers_mutex_;
  mutable std::vector<std::unique_ptr<LayerBuffers>> free_buffers_;
};

}  // namespace trivox
