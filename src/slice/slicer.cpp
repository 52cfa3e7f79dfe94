#include "trivox/slice/slicer.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_tracer.h"
#include "scanline.h"
#include "trivox/error.h"
#include "trivox/raster/dither.h"

namespace trivox {

struct Slicer::CellData {
  const Cell* cell;
  detail::BoundaryMesh mesh;
  GlobalSolver solver;

  CellData(const Cell& c, double tolerance_mm) : cell(&c), mesh(c.volume, tolerance_mm), solver(c.volume) {}
};

Slicer::Slicer(const Scene& scene, SliceParams params) : scene_(scene), params_(std::move(params)) {
  params_.validate();
  scene.printer.validate();
  dither_ = params_.dither.value_or(scene.dithering.value_or(DitherParams{}));
  dither_.validate();
  outline_tolerance_mm_ = params_.outline_tolerance_mm.value_or(
      0.25 * std::min({scene.printer.pitch_x_mm(), scene.printer.pitch_y_mm(), scene.printer.layer_thickness_mm}));
  // The control points' box holds every cell, so its layout bounds the final one: checking it
  // first refuses a job too large to lay out before any outline is built.
  try {
    const Box3 hull = scene.bounds();
    if (!hull.empty()) make_layout(hull, scene.printer);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", scene.source, e.what()));
  }
  Box3 bounds;
  for (const Cell& c : scene.cells) {
    cells_.push_back(std::make_unique<CellData>(c, outline_tolerance_mm_));
    bounds.expand(cells_.back()->mesh.bounds());
  }
  // The meshes lie within the tolerance of the true boundary.
  const Vec3 grow{outline_tolerance_mm_, outline_tolerance_mm_, outline_tolerance_mm_};
  if (!bounds.empty()) bounds = Box3{bounds.lo - grow, bounds.hi + grow};
  layout_ = make_layout(bounds, scene.printer);
}

Slicer::~Slicer() = default;

LayerResult Slicer::slice_layer(int layer) const {
  const auto start = std::chrono::steady_clock::now();
  const SliceLayout& L = layout_;
  const int m = scene_.num_materials();
  LayerResult result;
  LayerStats& st = result.stats;
  st.layer = layer;
  st.z_mm = L.z_of_layer(layer);
  st.pixels_total = static_cast<std::int64_t>(L.width_px) * L.height_px;

  MaterialGrid grid(L.width_px, L.height_px, m);
  InsideMask inside(L.width_px, L.height_px, 0);
  std::vector<detail::Segment2> segments;
  detail::RowSpans spans;
  detail::TracedRow row_out;
  std::vector<float> fractions;
  detail::TraceCounters counters;

  // Cells in scene order; a later cell with non-empty material overwrites an earlier one
  // (the paper's rule for the pixels on shared boundaries).
  using Clock = std::chrono::steady_clock;
  auto lap = [](Clock::time_point& t) {
    const auto now = Clock::now();
    const double d = std::chrono::duration<double>(now - t).count();
    t = now;
    return d;
  };
  auto t = Clock::now();
  for (const auto& cd : cells_) {
    cd->mesh.cut(st.z_mm, segments);
    if (segments.empty()) continue;
    detail::candidate_spans(segments, L, 2.0 * outline_tolerance_mm_, spans);
    detail::CellTracer tracer(cd->cell->volume, cd->solver, params_, L.width_px);
    tracer.begin_layer(st.z_mm);
    for (int r = 0; r < L.height_px; ++r) {
      const auto& row_spans = spans[static_cast<std::size_t>(r)];
      if (row_spans.empty()) continue;
      tracer.trace_row(L, r, row_spans, row_out);
      st.seconds_inverse += lap(t);
      const std::size_t n = row_out.cols.size();
      if (n == 0) continue;
      fractions.assign(n * static_cast<std::size_t>(m), 0.0f);
      // Scene cells carry their material already wrapped in the scene's fraction policy
      // (CheckedMaterial), and dithering validates what reaches it.
      cd->cell->material->evaluate_row(row_out.uvw, row_out.xyz, fractions);
      for (std::size_t k = 0; k < n; ++k) {
        const int col = row_out.cols[k];
        inside.at(col, r) = 1;
        const float* f = fractions.data() + k * static_cast<std::size_t>(m);
        float sum = 0.0f;
        for (int j = 0; j < m; ++j) sum += f[j];
        if (sum <= 0.0f) continue;
        auto px = grid.pixel(col, r);
        std::copy(f, f + m, px.begin());
      }
      st.seconds_material += lap(t);
    }
    counters += tracer.counters();
  }

  st.seconds_inverse += lap(t);
  result.labels = dither(grid, inside, dither_, layer);
  st.seconds_dither = lap(t);
  st.voxels_per_material.assign(static_cast<std::size_t>(m), 0);
  for (std::uint8_t label : result.labels.values())
    if (label != LabelImage::kVoid) ++st.voxels_per_material[static_cast<std::size_t>(label - 1)];
  for (std::uint8_t v : inside.values()) st.pixels_inside += v;
  st.candidates = counters.candidates;
  st.global_calls = counters.global_calls;
  st.newton_evals = counters.newton_evals;
  st.folded_pixels = counters.folded;
  st.unresolved_pixels = counters.unresolved;
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace trivox
