// Slicing one layer of a scene: outline, inverse per pixel, material, dithering (Algorithm 1).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "trivox/raster/greyscale.h"
#include "trivox/raster/material_grid.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"
#include "trivox/slice/slice_stats.h"

namespace trivox {

// A layer as the dithering received it, for callers that look at the material field itself
// (the Python API's slice_layer(..., fractions=True)): the fractions the owning cells' materials
// gave every pixel (all 0 outside the cells) and the inside mask.
struct LayerRasters {
  MaterialGrid fractions;
  InsideMask inside;
};

// What a layer returns beyond its labels, grey and statistics (Slicer::slice_layer).
struct LayerRequest {
  bool owner = false;    // LayerResult::owner
  bool rasters = false;  // LayerResult::rasters
};

// One sliced layer, each raster width_px x height_px of the slicer's layout, row-major.
struct LayerResult {
  LabelImage labels;  // 0 = void / background, 1 + j = scene material j
  LayerStats stats;
  // The scene's greyscale exposure (Scene::greyscale), the size of `labels`; empty when the
  // scene has no greyscale block.
  GreyImage grey;
  // With LayerRequest::owner (else empty): the index of the scene cell each pixel belongs to,
  // or -1 outside every cell. Where cells overlap (shared faces of a multi-patch model), the
  // owner is the last cell in scene order that gives the pixel a non-empty material, else the
  // last that contains it; its material is the pixel's.
  std::vector<int> owner;
  // With LayerRequest::rasters (else empty): the layer before dithering. dither() of its
  // fractions and mask with Slicer::dither_params() and the layer's index gives `labels`.
  LayerRasters rasters;
};

// Slices a scene layer by layer (Algorithm 1): built from a scene and the slicing parameters,
// it prepares every cell once (boundary mesh, global solver, trims) and lays out the bitmap
// and the layers; then each layer is sliced on its own, from any thread.
class Slicer {
 public:
  // `scene` must outlive the slicer. Throws trivox::Error for invalid parameters, a model too
  // large to lay out or too far from the origin, or a trim shell that is not closed; throws
  // CancelledError when params.stop is raised while preparing.
  Slicer(const Scene& scene, SliceParams params);
  ~Slicer();
  Slicer(const Slicer&) = delete;
  Slicer& operator=(const Slicer&) = delete;

  const SliceLayout& layout() const noexcept;
  // The object's box in model space (mm) that the layout frames: per cell its volume's tight
  // image box, cut down to the box of every model-space trim it lies inside (a closed mesh's
  // vertices, a shell's control points, a trimming volume's image); the union over the cells.
  // Tighter than Scene::bounds(), the control points' box.
  const Box3& object_bounds() const noexcept;
  const SliceParams& params() const noexcept;
  const Scene& scene() const noexcept;
  // Bytes one worker holds while it slices a layer beyond the layer's rasters: the tracer's
  // rows in flight (a few rows of seeds and Jacobians per column of the bitmap), and the
  // traced rows of every trivariate that is traced once per layer for the trims it decides
  // (their solutions per pixel, all pixels counted). For the job estimate (job_estimate.h).
  std::uint64_t tracing_bytes_per_worker() const noexcept;
  // The dithering in effect: params().dither, else the scene's, else the defaults.
  const DitherParams& dither_params() const noexcept;

  // Slices layer `layer` (0 .. layout().num_layers - 1): its labels, grey and statistics.
  // Safe to call from several threads at once; the result depends only on the scene, the
  // parameters and `layer`. Throws trivox::Error for a layer out of range or a material
  // fraction outside the dithering's tolerance, CancelledError when params().stop is raised.
  LayerResult slice_layer(int layer) const;
  // The same, with the extras `request` asks for (LayerResult::owner, LayerResult::rasters).
  LayerResult slice_layer(int layer, const LayerRequest& request) const;

 private:
  // The prepared cells and a layer's steps (src/slice/slicer_parts.h).
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace trivox
