// LayerDecision: the candidate points of a cell in a layer, from its outline mesh narrowed
// by the trims that need no inverse of the cell (layer_decision.h).
#include <algorithm>

#include "layer_decision.h"
#include "trivox/cancel.h"

namespace trivox::detail {

namespace {
// Interior pixels traced beside the band of a constant-material cell (decide_cell).
constexpr int kSeedMarginPx = 8;
}  // namespace

bool LayerDecision::Trivariate::candidates(const SliceLayout& layout, double z_mm, std::vector<Segment2>& segments,
                                           RowSpans& spans, RowSpans* interior) const {
  if (fold) {
    fold->spans(layout, z_mm, band_mm, spans);
    return std::any_of(spans.begin(), spans.end(), [](const auto& row) { return !row.empty(); });
  }
  mesh.cut(z_mm, segments);
  if (segments.empty()) return false;
  candidate_spans(segments, layout, band_mm, spans, interior);
  return true;
}

bool LayerDecision::candidate_pixels(const Cell& cd, Layer& w, const RowSpans* only) const {
  const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd.trivariate)];
  if (!tv.candidates(layout_, w.z_mm, w.segments, w.spans, cd.fills_interior ? &w.interior : nullptr)) return false;
  if (only) {
    intersect_spans(w.spans, *only);
    if (cd.fills_interior) intersect_spans(w.interior, *only);
  }
  if (cd.model_space_clauses && params_.model_space_narrowing) narrow_to_model_space_clauses(cd, w);
  if (cd.parametric_outlines && params_.parametric_outlines) narrow_to_parametric_outlines(cd, w);
  if (cd.fills_interior) split_off_interior(tv, w);
  return true;
}

// A constant material needs no (u, v, w): of the interior the cut decides (w.interior), the
// pixels to fill are taken out of the candidates, and only the band around the outline is
// traced.
void LayerDecision::split_off_interior(const Trivariate& tv, Layer& w) const {
  const double band = tv.band_mm, z = w.z_mm;
  // Where a face lies nearly in the layer's plane, the mesh's small error across the face is
  // a wide one in the plane: no pixel within the band of a triangle that meets the slab of
  // the band's height around the layer is filled (such pixels are traced).
  tv.mesh.slab(z - band, z + band, w.slab_triangles);
  for (auto& row : w.outline_spans) row.clear();
  add_slab_spans(w.slab_triangles, z - band, z + band, layout_, band, w.outline_spans);
  merge_spans(w.outline_spans);
  subtract_spans(w.interior, w.outline_spans);
  // The band's pixels are traced with a few interior pixels beside them: solved, those seed
  // the band's pixels of the rows below (a pixel's seeds are its solved neighbours) and flood
  // back to the pixels just outside, so that Newton, failing on the face, hands the global
  // solver the face's normal.
  for (auto& row : w.interior) {
    std::size_t kept = 0;
    for (auto [c0, c1] : row)
      if (c0 + kSeedMarginPx <= c1 - kSeedMarginPx) row[kept++] = {c0 + kSeedMarginPx, c1 - kSeedMarginPx};
    row.resize(kept);
  }
  subtract_spans(w.spans, w.interior);
}

// Only pixels that pass the volume and shell clauses are worth inverting: those clauses are
// decided without this cell's inverse. A shell clause whose row its crossings decide alone
// (not a row through a seam's gap, nor a winding-number mesh with cones) is applied to the
// row's spans a stretch between crossings at a time; the other clauses pixel by pixel.
void LayerDecision::narrow_to_model_space_clauses(const Cell& cd, Layer& w) const {
  std::vector<std::pair<int, int>> kept_spans, runs;
  for (int r = 0; r < layout_.height_px; ++r) {
    auto& row_spans = w.spans[static_cast<std::size_t>(r)];
    bool per_pixel = false;
    for (const auto& k : cd.clauses) {
      if (row_spans.empty()) break;
      if (k.kind != TrimKind::kShell) {
        per_pixel = per_pixel || k.kind == TrimKind::kVolume;
        continue;
      }
      const auto slot = static_cast<std::size_t>(k.shell_slot);
      const auto& xs = w.shell_rows[slot][static_cast<std::size_t>(r)];
      if ((k.mesh->gap_tolerant() && xs.size() % 2 == 1) || (k.mesh->winding() && k.mesh->cone_count() > 0)) {
        per_pixel = true;
        continue;
      }
      crossing_runs(xs, k.mesh->winding() ? &w.shell_row_windings[slot][static_cast<std::size_t>(r)] : nullptr,
                    k.side == TrimSide::kInside, layout_, runs);
      intersect_row(row_spans, runs, kept_spans);
      row_spans.swap(kept_spans);
    }
    if (!per_pixel || row_spans.empty()) continue;
    // Pixel by pixel a clause may cost much (a winding number over a mesh with many cones): the
    // stop flag is read for every such row, so that a stopped job ends within a row.
    throw_if_stopped(params_.stop, "testing pixels against a cell's trims");
    kept_spans.clear();
    for (const auto& [c0, c1] : row_spans)
      for (int col = c0; col <= c1; ++col) {
        if (!passes_model_space_clauses(cd, col, r, w)) continue;
        if (!kept_spans.empty() && kept_spans.back().second == col - 1)
          kept_spans.back().second = col;
        else
          kept_spans.push_back({col, col});
      }
    row_spans.swap(kept_spans);
  }
}

// Only pixels inside the outline of every "inside" parametric clause can pass it: the
// even-odd interior of its cut at this layer, widened by the margin of every outline, and
// every centre within the margin of the part of it within the margin above or below the
// layer (a nearly flat face of the trim).
void LayerDecision::narrow_to_parametric_outlines(const Cell& cd, Layer& w) const {
  const double margin = 2.0 * setup_.outline_tolerance_mm, z = w.z_mm;
  for (const auto& k : cd.clauses) {
    if (!k.outline || k.side != TrimSide::kInside) continue;
    k.outline->mesh().cut(z, w.segments);
    candidate_spans(w.segments, layout_, margin, w.outline_spans);
    k.outline->mesh().slab(z - margin, z + margin, w.slab_triangles);
    add_slab_spans(w.slab_triangles, z - margin, z + margin, layout_, margin, w.outline_spans);
    merge_spans(w.outline_spans);
    intersect_spans(w.spans, w.outline_spans);
  }
}

// Row r's interior pixels of a constant-material cell, each at its pixel centre, with the
// domain's centre for (u, v, w), which the material does not read.
const TracedRow& LayerDecision::interior_row(const Cell& cd, int r, Layer& w) const {
  TracedRow& row = w.filled;
  const Vec3 uvw = cd.cell->volume.domain().center();
  row.cols.clear();
  row.uvw.clear();
  row.xyz.clear();
  const double y = layout_.y_of_row(r);
  for (const auto& [c0, c1] : w.interior[static_cast<std::size_t>(r)])
    for (int c = c0; c <= c1; ++c) {
      row.cols.push_back(c);
      row.uvw.push_back(uvw);
      row.xyz.push_back({layout_.x_of_col(c), y, w.z_mm});
    }
  return row;
}

}  // namespace trivox::detail
