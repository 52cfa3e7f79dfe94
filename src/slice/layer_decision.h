// The one decision of the points of a layer: which cell contains each point (its volume
// inverted there, its trims), which cell owns it where cells overlap, and the owning cell's
// material there. The slicer makes it on the pixel grid; the edge coverage of greyscale
// layers (coverage.h) on its finer sub-sample grid, restricted to the spans of its edge
// pixels. Any grid works: a SliceLayout of any pitch and origin, and spans of its points.
//
// Steps, per layer: the trivariates that trim some cell are traced once for the whole layer
// and the trimming shells cut once; then, cell by cell in scene order, the candidate points
// (the outline's cut widened by the band, narrowed by the trims that need no inverse of this
// cell), traced, kept by the trims, and their material evaluated; each decided row goes to the
// caller's consumer, which applies the owner rule (claim_point) as it writes what it keeps.
// Private to the slice layer.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "cell_tracer.h"
#include "fold_candidates.h"
#include "scanline.h"
#include "trivox/inverse/invert.h"
#include "trivox/mesh/sliced_mesh.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/layout.h"
#include "trivox/slice/slice_params.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox::detail {

// The owner rule for the points where cells overlap (shared faces of a multi-patch model, the
// paper's rule): a later cell in scene order that gives the point a non-empty material
// overwrites and owns it; a later cell that gives it none owns it only while no cell gave it
// material. Returns whether `cell`'s material becomes the point's.
inline bool claim_point(int cell, bool gives_material, int& owner, std::uint8_t& owner_gave_material) noexcept {
  if (!gives_material) {
    if (!owner_gave_material) owner = cell;
    return false;
  }
  owner = cell;
  owner_gave_material = 1;
  return true;
}

class LayerDecision {
 public:
  // The tolerances the decision is prepared at: the slicer's are an eighth of the finest pitch
  // of the pixels, the edge coverage's an eighth of its sub-samples' (everything else is
  // prepared the same way for both, so that they decide a point alike).
  struct Setup {
    double outline_tolerance_mm = 0;  // of the trivariates' outline meshes
    double shell_tolerance_mm = 0;    // of the model-space trim shells' meshes
  };

  // One trivariate, inverted once per point and layer however many cells use it.
  struct Trivariate {
    const Volume* volume;
    GlobalSolver solver;
    Box3 image;       // the tight box of V over its domain (GlobalSolver::image_bounds)
    SlicedMesh mesh;  // the outline mesh (boundary_mesh.h)
    // Half-width (mm) of the band around the outline whose points the exact inverse decides.
    double band_mm = 0;
    // Traced for the whole layer before the cells (it trims some cell), rather than streamed
    // row by row for the one cell it parametrizes.
    bool traced_first = false;
    // A folded volume the scene accepts (Cell::folds): candidates from its pieces' boxes, every
    // point by the global solver (fold_candidates.h, CellTracer).
    std::optional<FoldCandidates> fold;

    explicit Trivariate(const Volume& v) : volume(&v), solver(v) {}

    // The layer's candidate points into `spans` (the outline's cut widened by the band, or the
    // fold's boxes); false when there are none. With `interior` (never for a fold), also the
    // points the cut decides inside (candidate_spans).
    bool candidates(const SliceLayout& layout, double z_mm, std::vector<Segment2>& segments, RowSpans& spans,
                    RowSpans* interior = nullptr) const;
  };

  // A cell's trim clause, prepared.
  struct Clause {
    TrimKind kind;
    TrimSide side;
    int trivariate = -1;                    // kVolume
    std::shared_ptr<const ShellMesh> mesh;  // kShell (model space), kParametric (u, v, w)
    // kParametric: `mesh` mapped through the cell's volume, the clause's outline in model
    // space (the points an "inside" clause keeps lie inside it, or within the outline margin).
    std::shared_ptr<const ShellMesh> outline;
    int shell_slot = -1;  // kShell: index of its cut in the layer's cuts
    const TrimClause* source = nullptr;
  };

  struct Cell {
    const trivox::Cell* cell;
    int trivariate;
    std::vector<Clause> clauses;
    bool model_space_clauses = false;  // any kVolume or kShell clause
    bool parametric_clauses = false;
    bool parametric_outlines = false;  // any "inside" kParametric clause with an outline
    // One constant material, no clauses, no greyscale source (SliceParams::fill_constant_interiors).
    bool fills_interior = false;
  };

  // A decided row: the points of row `row` that cell `cell` contains (increasing columns),
  // their fractions (m per point, point-major) and, for a cell with a greyscale source, the
  // source's value at each. Valid during the consumer's call only.
  struct DecidedRow {
    int cell;
    int row;
    const TracedRow& points;
    std::span<const float> fractions;
    std::span<const float> grey_source;
  };
  using Consumer = std::function<void(const DecidedRow&)>;

  // What one decide() call works on: the trims' state for the layer, scratch reused from cell
  // to cell, the counters and the stage clock. One per concurrent call.
  struct Layer {
    double z_mm = 0;
    std::vector<std::vector<TracedRow>> traced_rows;           // per trivariate (empty unless traced first)
    std::vector<std::vector<std::uint8_t>> traced_inside;      // per trivariate, width x height
    std::vector<std::vector<std::vector<double>>> shell_rows;  // per cut shell: crossings per row
    // Per cut shell decided by its winding number: the windings beyond each crossing, per row.
    std::vector<std::vector<std::vector<int>>> shell_row_windings;

    std::vector<Segment2> segments;
    std::vector<int> directions;
    RowSpans spans, outline_spans, interior;
    TracedRow filled, kept;
    std::vector<std::array<Vec3, 3>> slab_triangles;
    std::vector<float> fractions, grey_scratch;
    TraceCounters counters;
    double seconds_inverse = 0, seconds_material = 0;

    // The stage clock: lap() returns the seconds since the previous lap.
    std::chrono::steady_clock::time_point clock = std::chrono::steady_clock::now();
    double lap() {
      const auto now = std::chrono::steady_clock::now();
      const double d = std::chrono::duration<double>(now - clock).count();
      clock = now;
      return d;
    }
  };

  // Plans the trivariates (each with its global solver) and the cells' clauses; `params`
  // must outlive the decision. Then, in order: bound_images, build_meshes, set_layout.
  LayerDecision(const Scene& scene, const SliceParams& params, Setup setup);

  // Every trivariate's tight image box, to within `tolerance_mm`.
  void bound_images(double tolerance_mm);
  // The outline meshes within `budgets` vertices (one per trivariate), then the trim shells'.
  void build_meshes(const std::vector<std::int64_t>& budgets);
  // The grid of the points decided.
  void set_layout(const SliceLayout& layout) { layout_ = layout; }

  // Decides the points of the layer at height z_mm, restricted to `only` (merged spans per
  // row of the layout) when given, and hands every decided row to `consumer`: cells in scene
  // order, each cell's rows in increasing order. Safe to call from several threads at once
  // with a Layer each.
  void decide(Layer& w, double z_mm, const RowSpans* only, const Consumer& consumer) const;

  // Whether the point (col, row) of the layer lies on the side of shell clause `k` it keeps
  // (the layer's shell cut by cut_trimming_shells): one test for every inside rule.
  bool passes_shell_clause(const Clause& k, int col, int row, const Layer& w) const;

  const std::vector<std::unique_ptr<Trivariate>>& trivariates() const noexcept { return trivariates_; }
  const std::vector<std::unique_ptr<Cell>>& cells() const noexcept { return cells_; }
  const SliceLayout& layout() const noexcept { return layout_; }
  const Setup& setup() const noexcept { return setup_; }

 private:
  void trace_trimming_volumes(Layer& w, const RowSpans* only) const;
  void cut_trimming_shells(Layer& w) const;
  void decide_cell(int cell, Layer& w, const RowSpans* only, const Consumer& consumer) const;
  // Throws FractionError at the scene's greyscale source: sample k of `row` is `value`, no number.
  [[noreturn]] void throw_grey_not_finite(const trivox::Cell& cell, const TracedRow& row, std::size_t k,
                                          float value) const;
  void decide_row(int cell, int row, const TracedRow& traced, bool test_model_space, Layer& w,
                  const Consumer& consumer) const;
  bool candidate_pixels(const Cell& cd, Layer& w, const RowSpans* only) const;
  void narrow_to_model_space_clauses(const Cell& cd, Layer& w) const;
  void narrow_to_parametric_outlines(const Cell& cd, Layer& w) const;
  void split_off_interior(const Trivariate& tv, Layer& w) const;
  bool passes_model_space_clauses(const Cell& cd, int col, int row, const Layer& w) const;
  static bool passes_parametric_clauses(const Cell& cd, Vec3 uvw);
  const TracedRow& kept_by_trims(const Cell& cd, int row, const TracedRow& traced, bool test_model_space,
                                 Layer& w) const;
  const TracedRow& interior_row(const Cell& cd, int row, Layer& w) const;

  const Scene& scene_;
  const SliceParams& params_;
  Setup setup_;
  SliceLayout layout_;
  // Every trivariate a cell uses, once: the scene's named volumes that are used (as a
  // parametrization or a trim), then each other cell's own volume.
  std::vector<std::unique_ptr<Trivariate>> trivariates_;
  std::vector<std::unique_ptr<Cell>> cells_;
};

}  // namespace trivox::detail
