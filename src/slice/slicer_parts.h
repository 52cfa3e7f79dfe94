// The slicer's prepared state and a layer's working state, shared by the preparation
// (slicer.cpp) and the per-layer steps (slice_layer.cpp). Private to the slice layer.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "coverage.h"
#include "layer_decision.h"
#include "trivox/slice/slicer.h"

namespace trivox {

struct Slicer::Impl {
  // A layer's dense rasters, handed out all zero and handed back all zero: the slicer clears
  // only the span of each row that a layer wrote (every written grid pixel is an inside pixel).
  struct LayerBuffers {
    MaterialGrid grid;
    InsideMask inside;
    std::vector<std::pair<int, int>> written;  // per row: first and last column written, or {1, 0}

    LayerBuffers(int width_px, int height_px, int num_materials)
        : grid(width_px, height_px, num_materials),
          inside(width_px, height_px, 0),
          written(static_cast<std::size_t>(height_px), {1, 0}) {}

    void clear();
  };

  // Everything one slice_layer call works on beyond the decision's state for the layer: its
  // buffers, the owners of overlapping cells' pixels and the counters.
  struct LayerWork : detail::LayerDecision::Layer {
    LayerWork(LayerStats& s, std::unique_ptr<LayerBuffers> b) : stats(s), buffers(std::move(b)) {}

    LayerStats& stats;
    std::unique_ptr<LayerBuffers> buffers;
    // With one cell, a pixel's owner is that cell wherever the pixel is inside: no per-pixel
    // bookkeeping (at Voxel Print resolution it would be 5 bytes a pixel, 37 MB a layer).
    bool several_cells = false;
    std::vector<int> owner;                         // per pixel with several cells: owning cell or -1
    std::vector<std::uint8_t> owner_gave_material;  // per pixel: the owner gave it a material
    // Greyscale from a scalar source (coverage.h): its value per pixel where a cell gives
    // material.
    std::vector<float> grey_values{};
  };

  Impl(const Scene& scene, SliceParams params);

  void check_model_fits(double finest_pitch_mm) const;
  Box3 tight_object_bounds() const;
  void lay_out(double finest_pitch_mm);
  void build_meshes();
  std::unique_ptr<LayerBuffers> take_buffers() const;
  void give_back(std::unique_ptr<LayerBuffers> buffers) const;

  // The steps of slice_layer (slice_layer.cpp).
  LayerResult slice_layer(int layer, const LayerRequest& request) const;
  void paint_row(const detail::LayerDecision::DecidedRow& row, LayerWork& w) const;
  void count_labels(LayerResult& result, LayerWork& w, bool owner_out) const;

  const Scene& scene;
  SliceParams params;
  DitherParams dither;
  double outline_tolerance_mm = 0;
  SliceLayout layout;
  Box3 object_bounds;  // what the layout frames (Slicer::object_bounds)
  // The trivariates, the cells and their trims, prepared for the pixel grid (layer_decision.h).
  std::unique_ptr<detail::LayerDecision> decision;
  // The layers' material grids and inside masks, reused by the layers that follow: at
  // printer resolution they are tens of megabytes, and fresh ones cost every layer the
  // faulting-in and clearing of their pages. One per concurrent slice_layer call at most.
  mutable std::mutex buffers_mutex;
  mutable std::vector<std::unique_ptr<LayerBuffers>> free_buffers;
  // Greyscale scenes with anti-aliasing: the sub-sampling of edge pixels.
  std::unique_ptr<detail::EdgeCoverage> coverage;
};

}  // namespace trivox
