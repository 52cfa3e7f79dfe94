// Slicing one layer of a scene: outline, inverse per pixel, material, dithering (Algorithm 1).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"
#include "trivox/slice/slice_stats.h"

namespace trivox {

namespace detail {
struct TracedRow;
}

struct LayerResult {
  LabelImage labels;  // 0 = void / background, 1 + j = scene material j
  LayerStats stats;
  // The scene's greyscale exposure (Scene::greyscale), the size of `labels`; empty when the
  // scene has no greyscale block.
  GreyImage grey;
};

namespace detail {
class EdgeCoverage;
}

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
  // Bytes one worker holds while it slices a layer beyond the layer's rasters: the tracer's
  // rows in flight (a few rows of seeds and Jacobians per column of the bitmap), and the
  // traced rows of every trivariate that is traced once per layer for the trims it decides
  // (their solutions per pixel, all pixels counted). For the job estimate (job_estimate.h).
  std::uint64_t tracing_bytes_per_worker() const noexcept;
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
  // Prepared once (slicer.cpp); a layer's state (slicer_parts.h).
  struct Trivariate;
  struct CellData;
  struct LayerBuffers;
  struct LayerWork;
  void check_model_fits(double finest_pitch_mm) const;
  void prepare_cells();
  void lay_out(double finest_pitch_mm);
  void build_meshes(double finest_pitch_mm);
  std::unique_ptr<LayerBuffers> take_buffers() const;
  void give_back(std::unique_ptr<LayerBuffers> buffers) const;

  // The steps of slice_layer (slice_layer.cpp).
  void trace_trimming_volumes(LayerWork& w) const;
  void cut_trimming_shells(LayerWork& w) const;
  void slice_cell(int cell, LayerWork& w) const;
  bool candidate_pixels(const CellData& cd, LayerWork& w) const;
  void narrow_to_model_space_clauses(const CellData& cd, LayerWork& w) const;
  void narrow_to_parametric_outlines(const CellData& cd, LayerWork& w) const;
  void split_off_interior(const Trivariate& tv, LayerWork& w) const;
  bool passes_model_space_clauses(const CellData& cd, int col, int row, const LayerWork& w) const;
  static bool passes_parametric_clauses(const CellData& cd, Vec3 uvw);
  const detail::TracedRow& kept_by_trims(const CellData& cd, int row, const detail::TracedRow& traced,
                                         bool test_model_space, detail::TracedRow& kept, const LayerWork& w) const;
  const detail::TracedRow& interior_row(const CellData& cd, int row, LayerWork& w) const;
  void paint_row(int cell, int row, const detail::TracedRow& traced, LayerWork& w) const;
  void count_labels(LayerResult& result, LayerWork& w, std::vector<int>* owner) const;

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
  // Greyscale scenes with anti-aliasing: the sub-sampling of edge pixels.
  std::unique_ptr<detail::EdgeCoverage> coverage_;
};

}  // namespace trivox
