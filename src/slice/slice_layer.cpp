// Slicer::slice_layer, Algorithm 1 for one layer, as named steps: trace the trimming
// volumes and cut the trimming shells once for the layer; then, cell by cell in scene order,
// find the candidate pixels, trace them, keep those the trims allow and paint them with the
// cell's material; finally dither the grid and count the labels.
#include <algorithm>
#include <optional>

#include "check.h"
#include "coverage.h"
#include "function_clones.h"
#include "slicer_parts.h"
#include "trivox/material/material_function.h"
#include "trivox/raster/dither.h"

namespace trivox {

namespace {
// Interior pixels traced beside the band of a constant-material cell (slice_cell).
constexpr int kSeedMarginPx = 8;
}  // namespace

LayerResult Slicer::slice_layer(int layer) const { return slice_layer(layer, nullptr); }

LayerResult Slicer::slice_layer(int layer, std::vector<int>* owner_out) const {
  return slice_layer(layer, owner_out, nullptr);
}

LayerResult Slicer::slice_layer(int layer, std::vector<int>* owner_out, LayerRasters* rasters) const {
  const auto start = std::chrono::steady_clock::now();
  LayerResult result;
  LayerStats& st = result.stats;
  st.layer = layer;
  st.z_mm = layout_.z_of_layer(layer);
  st.pixels_total = static_cast<std::int64_t>(layout_.width_px) * layout_.height_px;

  // The buffers are not handed back when the layer throws: a buffer in the pool is always
  // all zero.
  LayerWork w(st, take_buffers());
  w.several_cells = cells_.size() > 1;
  const auto owned_pixels = w.several_cells ? static_cast<std::size_t>(st.pixels_total) : 0;
  w.owner.assign(owned_pixels, -1);
  w.owner_gave_material.assign(owned_pixels, 0);
  if (scene_.greyscale && scene_.greyscale->material < 0)
    w.grey_values.assign(static_cast<std::size_t>(st.pixels_total), 0.0f);

  trace_trimming_volumes(w);
  cut_trimming_shells(w);
  st.seconds_inverse += w.lap();
  // Cells in scene order; a later cell with non-empty material overwrites an earlier one
  // (the paper's rule for the pixels on shared boundaries), and owns the pixel.
  for (std::size_t ci = 0; ci < cells_.size(); ++ci) slice_cell(static_cast<int>(ci), w);
  st.seconds_inverse += w.lap();

  if (rasters) {
    rasters->fractions = w.buffers->grid;
    rasters->inside = w.buffers->inside;
  }
  detail::dither_checked_grid(w.buffers->grid, w.buffers->inside, dither_, result.labels, layer);
  // Greyscale (coverage.h): every pixel's grey from the grid, the edge pixels' from sub-samples.
  if (scene_.greyscale) {
    result.grey = detail::grey_from_grid(w.buffers->grid, w.buffers->written, *scene_.greyscale, w.grey_values);
    if (coverage_) coverage_->antialias(layer, result.grey);
  }
  st.seconds_dither = w.lap();
  count_labels(result, w, owner_out);
  static_cast<TraceCounters&>(st) = w.counters;
  give_back(std::move(w.buffers));
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

bool Slicer::Trivariate::candidates(const SliceLayout& layout, double z_mm, std::vector<Segment2>& segments,
                                    detail::RowSpans& spans, detail::RowSpans* interior) const {
  if (fold) {
    fold->spans(layout, z_mm, band_mm, spans);
    return std::any_of(spans.begin(), spans.end(), [](const auto& row) { return !row.empty(); });
  }
  mesh.cut(z_mm, segments);
  if (segments.empty()) return false;
  detail::candidate_spans(segments, layout, band_mm, spans, interior);
  return true;
}

// The trivariates that trim some cell are traced once for the whole layer, so every Boolean
// clause and every cell they parametrize read the same inside set (the cells "A only", "B
// only", "A and B" then partition the union by construction).
void Slicer::trace_trimming_volumes(LayerWork& w) const {
  const SliceLayout& L = layout_;
  const auto width = static_cast<std::size_t>(L.width_px);
  w.traced_rows.resize(trivariates_.size());
  w.traced_inside.resize(trivariates_.size());
  for (std::size_t k = 0; k < trivariates_.size(); ++k) {
    const Trivariate& tv = *trivariates_[k];
    if (!tv.traced_first) continue;
    auto& rows = w.traced_rows[k];
    auto& in = w.traced_inside[k];
    rows.resize(static_cast<std::size_t>(L.height_px));
    in.assign(static_cast<std::size_t>(w.stats.pixels_total), 0);
    if (!tv.candidates(L, w.stats.z_mm, w.segments, w.spans)) continue;
    detail::CellTracer tracer(*tv.volume, tv.solver, params_, L.width_px, detail::CellTracer::kDefaultRowsInFlight,
                              tv.fold.has_value());
    tracer.trace_layer(L, w.stats.z_mm, w.spans, [&](int r, const detail::TracedRow& row) {
      rows[static_cast<std::size_t>(r)] = row;
      for (int col : row.cols) in[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(col)] = 1;
    });
    w.counters += tracer.counters();
  }
}

// Each model-space shell is cut once and its crossings with every row's centre line kept.
void Slicer::cut_trimming_shells(LayerWork& w) const {
  for (const auto& cd : cells_)
    for (const auto& k : cd->clauses)
      if (k.shell_slot >= 0) {
        const auto slot = static_cast<std::size_t>(k.shell_slot);
        if (w.shell_rows.size() <= slot) w.shell_rows.resize(slot + 1);
        if (k.mesh->winding()) {
          // A mesh trim by the winding-number rule: the crossings signed (shell_mesh.h).
          if (w.shell_row_windings.size() <= slot) w.shell_row_windings.resize(slot + 1);
          k.mesh->mesh().cut(w.stats.z_mm, w.segments, w.directions);
          detail::shell_row_windings(w.segments, w.directions, layout_, w.shell_rows[slot], w.shell_row_windings[slot]);
          continue;
        }
        k.mesh->mesh().cut(w.stats.z_mm, w.segments);
        detail::shell_row_crossings(w.segments, layout_, w.shell_rows[slot]);
      }
}

bool Slicer::passes_model_space_clauses(const CellData& cd, int col, int row, const LayerWork& w) const {
  const SliceLayout& L = layout_;
  for (const auto& k : cd.clauses) {
    bool in;
    if (k.kind == TrimKind::kVolume) {
      in = w.traced_inside[static_cast<std::size_t>(k.trivariate)]
                          [static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) +
                           static_cast<std::size_t>(col)] != 0;
    } else if (k.kind == TrimKind::kShell) {
      const auto& xs = w.shell_rows[static_cast<std::size_t>(k.shell_slot)][static_cast<std::size_t>(row)];
      if (k.mesh->winding()) {
        const auto& windings =
            w.shell_row_windings[static_cast<std::size_t>(k.shell_slot)][static_cast<std::size_t>(row)];
        const double x = L.x_of_col(col);
        in = k.mesh->winding_inside(detail::winding_beyond(xs, windings, x), {x, L.y_of_row(row), w.stats.z_mm});
      } else {
        // A row through a seam's gap of a trimmed-surface shell is crossed an odd number of
        // times: its pixels are decided by the shell's vote (shell_mesh.h).
        in = k.mesh->gap_tolerant() && xs.size() % 2 == 1
                 ? k.mesh->contains({L.x_of_col(col), L.y_of_row(row), w.stats.z_mm})
                 : detail::inside_crossings(xs, L.x_of_col(col));
      }
    } else {
      continue;
    }
    if (in != (k.side == TrimSide::kInside)) return false;
  }
  return true;
}

bool Slicer::passes_parametric_clauses(const CellData& cd, Vec3 uvw) {
  for (const auto& k : cd.clauses)
    if (k.kind == TrimKind::kParametric && k.mesh->contains(uvw) != (k.side == TrimSide::kInside)) return false;
  return true;
}

bool Slicer::candidate_pixels(const CellData& cd, LayerWork& w) const {
  const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd.trivariate)];
  if (!tv.candidates(layout_, w.stats.z_mm, w.segments, w.spans, cd.fills_interior ? &w.interior : nullptr))
    return false;
  if (cd.model_space_clauses && params_.model_space_narrowing) narrow_to_model_space_clauses(cd, w);
  if (cd.parametric_outlines && params_.parametric_outlines) narrow_to_parametric_outlines(cd, w);
  if (cd.fills_interior) split_off_interior(tv, w);
  return true;
}

// A constant material needs no (u, v, w): of the interior the cut decides (w.interior), the
// pixels to fill are taken out of the candidates, and only the band around the outline is
// traced.
void Slicer::split_off_interior(const Trivariate& tv, LayerWork& w) const {
  const double band = tv.band_mm, z = w.stats.z_mm;
  // Where a face lies nearly in the layer's plane, the mesh's small error across the face is
  // a wide one in the plane: no pixel within the band of a triangle that meets the slab of
  // the band's height around the layer is filled (such pixels are traced).
  tv.mesh.slab(z - band, z + band, w.slab_triangles);
  for (auto& row : w.outline_spans) row.clear();
  detail::add_slab_spans(w.slab_triangles, z - band, z + band, layout_, band, w.outline_spans);
  detail::merge_spans(w.outline_spans);
  detail::subtract_spans(w.interior, w.outline_spans);
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
  detail::subtract_spans(w.spans, w.interior);
}

// Only pixels that pass the volume and shell clauses are worth inverting: those clauses are
// decided without this cell's inverse. A shell clause whose row its crossings decide alone
// (not a row through a seam's gap, nor a winding-number mesh with cones) is applied to the
// row's spans a stretch between crossings at a time; the other clauses pixel by pixel.
void Slicer::narrow_to_model_space_clauses(const CellData& cd, LayerWork& w) const {
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
      detail::crossing_runs(xs, k.mesh->winding() ? &w.shell_row_windings[slot][static_cast<std::size_t>(r)] : nullptr,
                            k.side == TrimSide::kInside, layout_, runs);
      detail::intersect_row(row_spans, runs, kept_spans);
      row_spans.swap(kept_spans);
    }
    if (!per_pixel || row_spans.empty()) continue;
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
void Slicer::narrow_to_parametric_outlines(const CellData& cd, LayerWork& w) const {
  const double margin = 2.0 * outline_tolerance_mm_, z = w.stats.z_mm;
  for (const auto& k : cd.clauses) {
    if (!k.outline) continue;
    k.outline->mesh().cut(z, w.segments);
    detail::candidate_spans(w.segments, layout_, margin, w.outline_spans);
    k.outline->mesh().slab(z - margin, z + margin, w.slab_triangles);
    detail::add_slab_spans(w.slab_triangles, z - margin, z + margin, layout_, margin, w.outline_spans);
    detail::merge_spans(w.outline_spans);
    detail::intersect_spans(w.spans, w.outline_spans);
  }
}

void Slicer::slice_cell(int ci, LayerWork& w) const {
  const CellData& cd = *cells_[static_cast<std::size_t>(ci)];
  const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd.trivariate)];
  // The model-space clauses are tested on the traced pixels where they did not choose the
  // candidates.
  const bool test_model_space = tv.traced_first || (cd.model_space_clauses && !params_.model_space_narrowing);
  auto paint = [&](int r, const detail::TracedRow& traced) {
    const detail::TracedRow& row =
        cd.clauses.empty() ? traced : kept_by_trims(cd, r, traced, test_model_space, w.kept, w);
    w.stats.seconds_inverse += w.lap();
    paint_row(ci, r, row, w);
    w.stats.seconds_material += w.lap();
  };
  if (tv.traced_first) {
    // Traced already for the clauses it decides: its rows are read, not traced again.
    const auto& rows = w.traced_rows[static_cast<std::size_t>(cd.trivariate)];
    for (int r = 0; r < layout_.height_px; ++r) paint(r, rows[static_cast<std::size_t>(r)]);
    return;
  }
  if (!candidate_pixels(cd, w)) return;
  detail::CellTracer tracer(*tv.volume, tv.solver, params_, layout_.width_px, detail::CellTracer::kDefaultRowsInFlight,
                            tv.fold.has_value());
  tracer.trace_layer(layout_, w.stats.z_mm, w.spans, paint);
  w.counters += tracer.counters();
  // The interior split off from the candidates (split_off_interior), filled.
  if (cd.fills_interior)
    for (int r = 0; r < layout_.height_px; ++r)
      if (!w.interior[static_cast<std::size_t>(r)].empty()) paint(r, interior_row(cd, r, w));
}

// Row r's interior pixels of a constant-material cell, each at its pixel centre, with the
// domain's centre for (u, v, w), which the material does not read.
const detail::TracedRow& Slicer::interior_row(const CellData& cd, int r, LayerWork& w) const {
  detail::TracedRow& row = w.filled;
  const Vec3 uvw = cd.cell->volume.domain().center();
  row.cols.clear();
  row.uvw.clear();
  row.xyz.clear();
  const double y = layout_.y_of_row(r);
  for (const auto& [c0, c1] : w.interior[static_cast<std::size_t>(r)])
    for (int c = c0; c <= c1; ++c) {
      row.cols.push_back(c);
      row.uvw.push_back(uvw);
      row.xyz.push_back({layout_.x_of_col(c), y, w.stats.z_mm});
    }
  return row;
}

const detail::TracedRow& Slicer::kept_by_trims(const CellData& cd, int r, const detail::TracedRow& row,
                                               bool test_model_space, detail::TracedRow& kept,
                                               const LayerWork& w) const {
  if (!test_model_space && !cd.parametric_clauses) return row;
  kept.cols.clear();
  kept.uvw.clear();
  kept.xyz.clear();
  for (std::size_t k = 0; k < row.cols.size(); ++k) {
    if (test_model_space && !passes_model_space_clauses(cd, row.cols[k], r, w)) continue;
    if (cd.parametric_clauses && !passes_parametric_clauses(cd, row.uvw[k])) continue;
    kept.cols.push_back(row.cols[k]);
    kept.uvw.push_back(row.uvw[k]);
    kept.xyz.push_back(row.xyz[k]);
  }
  return kept;
}

// Gives cell `ci`'s material to the inside pixels of one row and marks them inside; checks
// the fractions as they are written (the dithering then need not read the grid twice).
TRIVOX_CLONED void Slicer::paint_row(int ci, int r, const detail::TracedRow& row, LayerWork& w) const {
  const std::size_t n = row.cols.size();
  if (n == 0) return;
  TRIVOX_CHECK_GE(row.cols.front(), 0);
  TRIVOX_CHECK_LT(row.cols.back(), layout_.width_px);
  TRIVOX_CHECK_EQ(row.uvw.size(), n);
  const CellData& cd = *cells_[static_cast<std::size_t>(ci)];
  const auto m = static_cast<std::size_t>(scene_.num_materials());
  const auto width = static_cast<std::size_t>(layout_.width_px);
  MaterialGrid& grid = w.buffers->grid;
  InsideMask& inside = w.buffers->inside;
  const float fraction_lo = -dither_.fraction_tolerance, fraction_hi = 1.0f + dither_.fraction_tolerance;
  // Every value is written by the material (MaterialFunction::evaluate_row).
  if (w.fractions.size() < n * m) w.fractions.resize(n * m);
  // Scene cells carry their material already wrapped in the scene's fraction policy
  // (CheckedMaterial); the copy into the grid below checks what reaches the dithering.
  cd.cell->material->evaluate_row(row.uvw, row.xyz, std::span<float>(w.fractions).first(n * m));
  if (cd.cell->grey_source)
    detail::grey_source_row(*cd.cell->grey_source, row, w.fractions, static_cast<int>(m), r, layout_.width_px,
                            w.grey_values, w.grey_scratch);
  // A traced row's columns increase: its span is its first and last.
  auto& [first_written, last_written] = w.buffers->written[static_cast<std::size_t>(r)];
  const bool row_unwritten = first_written > last_written;
  first_written = row_unwritten ? row.cols.front() : std::min(first_written, row.cols.front());
  last_written = row_unwritten ? row.cols.back() : std::max(last_written, row.cols.back());
  int fractions_ok = 1;
  for (std::size_t k = 0; k < n; ++k) {
    const int col = row.cols[k];
    const std::size_t at = static_cast<std::size_t>(r) * width + static_cast<std::size_t>(col);
    inside.at(col, r) = 1;
    const float* f = w.fractions.data() + k * m;
    float sum = 0.0f;
    for (std::size_t j = 0; j < m; ++j) sum += f[j];
    if (sum <= 0.0f) {
      if (w.several_cells && !w.owner_gave_material[at]) w.owner[at] = ci;
      continue;
    }
    if (w.several_cells) {
      w.owner[at] = ci;
      w.owner_gave_material[at] = 1;
    }
    float* px = grid.pixel(col, r).data();
    for (std::size_t j = 0; j < m; ++j) {
      px[j] = f[j];
      fractions_ok &= static_cast<int>(f[j] >= fraction_lo) & static_cast<int>(f[j] <= fraction_hi);
    }
    fractions_ok &= static_cast<int>(sum <= fraction_hi);
  }
  // The grid is checked as it is written, not again by the dithering (dither_checked_grid).
  if (!fractions_ok)
    for (int col : row.cols) grid.check_pixel(col, r, dither_.fraction_tolerance);
}

// Voxels per material and inside pixels over the written spans (outside them every pixel is
// outside and void), and pixels per owning cell.
void Slicer::count_labels(LayerResult& result, LayerWork& w, std::vector<int>* owner_out) const {
  LayerStats& st = w.stats;
  const int m = scene_.num_materials();
  const InsideMask& inside = w.buffers->inside;
  st.voxels_per_material.assign(static_cast<std::size_t>(m), 0);
  std::vector<std::int64_t> per_label(static_cast<std::size_t>(m) + 1, 0);
  for (int r = 0; r < layout_.height_px; ++r) {
    const auto [first, last] = w.buffers->written[static_cast<std::size_t>(r)];
    const std::uint8_t* labels = result.labels.row(r).data();
    const std::uint8_t* in = inside.row(r).data();
    for (int col = first; col <= last; ++col) {
      ++per_label[labels[col]];
      st.pixels_inside += in[col];
    }
  }
  for (int j = 0; j < m; ++j)
    st.voxels_per_material[static_cast<std::size_t>(j)] = per_label[static_cast<std::size_t>(j) + 1];
  st.pixels_per_cell.assign(cells_.size(), 0);
  if (w.several_cells) {
    for (int o : w.owner)
      if (o >= 0) ++st.pixels_per_cell[static_cast<std::size_t>(o)];
  } else {
    if (!cells_.empty()) st.pixels_per_cell[0] = st.pixels_inside;
    if (owner_out) {
      w.owner.resize(static_cast<std::size_t>(st.pixels_total));
      std::transform(inside.values().begin(), inside.values().end(), w.owner.begin(),
                     [](std::uint8_t in) { return in != 0 ? 0 : -1; });
    }
  }
  if (owner_out) *owner_out = std::move(w.owner);
}

}  // namespace trivox
