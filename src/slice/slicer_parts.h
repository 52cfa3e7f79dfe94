// The slicer's prepared state and a layer's working state, shared by the preparation
// (slicer.cpp) and the per-layer steps (slice_layer.cpp). Private to the slice layer.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "cell_tracer.h"
#include "fold_candidates.h"
#include "scanline.h"
#include "trivox/inverse/invert.h"
#include "trivox/mesh/sliced_mesh.h"
#include "trivox/slice/slicer.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {

// One trivariate, inverted once per pixel and layer however many cells use it.
struct Slicer::Trivariate {
  const Volume* volume;
  GlobalSolver solver;
  Box3 image;       // the tight box of V over its domain (GlobalSolver::image_bounds)
  SlicedMesh mesh;  // the outline mesh (boundary_mesh.h)
  // Half-width (mm) of the band around the outline whose pixels the exact inverse decides:
  // twice the mesh's distance from the true boundary.
  double band_mm = 0;
  // Traced for the whole layer before the cells (it trims some cell), rather than streamed
  // row by row for the one cell it parametrizes.
  bool traced_first = false;
  // A folded volume the scene accepts (Cell::folds): candidates from its pieces' boxes, every
  // pixel by the global solver (fold_candidates.h, CellTracer).
  std::optional<detail::FoldCandidates> fold;

  explicit Trivariate(const Volume& v) : volume(&v), solver(v) {}

  // The layer's candidate pixels into `spans` (the outline's cut widened by the band, or the
  // fold's boxes); false when there are none. With `interior` (never for a fold), also the
  // pixels the cut decides inside (detail::candidate_spans).
  bool candidates(const SliceLayout& layout, double z_mm, std::vector<Segment2>& segments, detail::RowSpans& spans,
                  detail::RowSpans* interior = nullptr) const;
};

struct Slicer::CellData {
  struct Clause {
    TrimKind kind;
    TrimSide side;
    int trivariate = -1;                    // kVolume
    std::shared_ptr<const ShellMesh> mesh;  // kShell (model space), kParametric (u, v, w)
    // kParametric inside: `mesh` mapped through the cell's volume, the clause's outline in
    // model space (the pixels it keeps lie inside it, or within the outline margin).
    std::shared_ptr<const ShellMesh> outline;
    int shell_slot = -1;  // kShell: index of its cut in the layer's cuts
    const TrimClause* source = nullptr;
  };
  const Cell* cell;
  int trivariate;
  std::vector<Clause> clauses;
  bool model_space_clauses = false;  // any kVolume or kShell clause
  bool parametric_clauses = false;
  bool parametric_outlines = false;  // any kParametric clause with an outline
  // One constant material, no clauses, no greyscale source (SliceParams::fill_constant_interiors).
  bool fills_interior = false;
};

// A layer's dense rasters, handed out all zero and handed back all zero: the slicer clears
// only the span of each row that a layer wrote (every written grid pixel is an inside pixel).
struct Slicer::LayerBuffers {
  MaterialGrid grid;
  InsideMask inside;
  std::vector<std::pair<int, int>> written;  // per row: first and last column written, or {1, 0}

  LayerBuffers(int width_px, int height_px, int num_materials)
      : grid(width_px, height_px, num_materials),
        inside(width_px, height_px, 0),
        written(static_cast<std::size_t>(height_px), {1, 0}) {}

  void clear();
};

// Everything one slice_layer call works on: its buffers, the trims' state for this layer,
// the owners of overlapping cells' pixels, scratch reused from cell to cell, the counters
// and the stage clock.
struct Slicer::LayerWork {
  LayerWork(LayerStats& s, std::unique_ptr<LayerBuffers> b) : stats(s), buffers(std::move(b)) {}

  LayerStats& stats;
  std::unique_ptr<LayerBuffers> buffers;
  // With one cell, a pixel's owner is that cell wherever the pixel is inside: no per-pixel
  // bookkeeping (at Voxel Print resolution it would be 5 bytes a pixel, 37 MB a layer).
  bool several_cells = false;
  std::vector<int> owner;                         // per pixel with several cells: owning cell or -1
  std::vector<std::uint8_t> owner_gave_material;  // per pixel: the owner gave it a material

  // The trivariates traced first and the cut shells, for the trim clauses.
  std::vector<std::vector<detail::TracedRow>> traced_rows;   // per trivariate (empty unless traced first)
  std::vector<std::vector<std::uint8_t>> traced_inside;      // per trivariate, width x height
  std::vector<std::vector<std::vector<double>>> shell_rows;  // per cut shell: crossings per row
  // Per cut shell decided by its winding number: the windings beyond each crossing, per row.
  std::vector<std::vector<std::vector<int>>> shell_row_windings;

  // Scratch.
  std::vector<Segment2> segments;
  std::vector<int> directions;
  detail::RowSpans spans, outline_spans, interior;
  detail::TracedRow filled;
  std::vector<std::array<Vec3, 3>> slab_triangles;
  detail::TracedRow kept;
  std::vector<float> fractions;
  TraceCounters counters;
  // Greyscale from a scalar source (coverage.h): its value per pixel where a cell gives
  // material, and scratch.
  std::vector<float> grey_values{}, grey_scratch{};

  // The stage clock: lap() returns the seconds since the previous lap.
  std::chrono::steady_clock::time_point clock = std::chrono::steady_clock::now();
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double d = std::chrono::duration<double>(now - clock).count();
    clock = now;
    return d;
  }
};

}  // namespace trivox
