// Slicer::slice_layer, Algorithm 1 for one layer: the layer's pixels decided
// (layer_decision.h: trims, candidates, inverse, owner and material), each decided row painted
// into the layer's material grid, then the grid dithered and the labels counted.
#include <algorithm>

#include "check.h"
#include "coverage.h"
#include "function_clones.h"
#include "slicer_parts.h"
#include "trivox/raster/dither.h"

namespace trivox {

LayerResult Slicer::Impl::slice_layer(int layer, const LayerRequest& request) const {
  const auto start = std::chrono::steady_clock::now();
  LayerResult result;
  LayerStats& st = result.stats;
  st.layer = layer;
  st.z_mm = layout.z_of_layer(layer);
  st.pixels_total = static_cast<std::int64_t>(layout.width_px) * layout.height_px;

  // The buffers are not handed back when the layer throws: a buffer in the pool is always
  // all zero.
  LayerWork w(st, take_buffers());
  w.several_cells = decision->cells().size() > 1;
  const auto owned_pixels = w.several_cells ? static_cast<std::size_t>(st.pixels_total) : 0;
  w.owner.assign(owned_pixels, -1);
  w.owner_gave_material.assign(owned_pixels, 0);
  if (scene.greyscale && scene.greyscale->material < 0)
    w.grey_values.assign(static_cast<std::size_t>(st.pixels_total), 0.0f);

  // Every pixel of the layer, cell by cell in scene order (layer_decision.h).
  decision->decide(w, st.z_mm, nullptr, [&](const detail::LayerDecision::DecidedRow& row) { paint_row(row, w); });
  st.seconds_inverse += w.seconds_inverse;
  st.seconds_material += w.seconds_material;

  if (request.rasters) {
    result.rasters.fractions = w.buffers->grid;
    result.rasters.inside = w.buffers->inside;
  }
  detail::dither_checked_grid(w.buffers->grid, w.buffers->inside, dither, result.labels, layer);
  // Greyscale (coverage.h): every pixel's grey from the grid, the edge pixels' from sub-samples.
  if (scene.greyscale) {
    result.grey = detail::grey_from_grid(w.buffers->grid, w.buffers->written, *scene.greyscale, w.grey_values);
    if (coverage) coverage->antialias(layer, result.grey);
  }
  st.seconds_dither = w.lap();
  count_labels(result, w, request.owner);
  static_cast<TraceCounters&>(st) = w.counters;
  give_back(std::move(w.buffers));
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

// Gives a decided row's material to its pixels and marks them inside, by the owner rule
// (claim_point); checks the fractions as they are written (the dithering then need not read
// the grid twice).
TRIVOX_CLONED void Slicer::Impl::paint_row(const detail::LayerDecision::DecidedRow& decided, LayerWork& w) const {
  const detail::TracedRow& row = decided.points;
  const int ci = decided.cell, r = decided.row;
  const std::size_t n = row.cols.size();
  TRIVOX_CHECK_GE(row.cols.front(), 0);
  TRIVOX_CHECK_LT(row.cols.back(), layout.width_px);
  TRIVOX_CHECK_EQ(row.uvw.size(), n);
  const auto m = static_cast<std::size_t>(scene.num_materials());
  const auto width = static_cast<std::size_t>(layout.width_px);
  MaterialGrid& grid = w.buffers->grid;
  InsideMask& inside = w.buffers->inside;
  const float fraction_lo = -dither.fraction_tolerance, fraction_hi = 1.0f + dither.fraction_tolerance;
  // The copy into the grid below checks what reaches the dithering.
  const float* fractions = decided.fractions.data();
  const bool grey_source = !decided.grey_source.empty();
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
    const float* f = fractions + k * m;
    float sum = 0.0f;
    for (std::size_t j = 0; j < m; ++j) sum += f[j];
    const bool gives_material = !(sum <= 0.0f);
    if (w.several_cells) detail::claim_point(ci, gives_material, w.owner[at], w.owner_gave_material[at]);
    if (!gives_material) continue;
    // Only where the cell gives material, as the grid is written: a later cell with material
    // overwrites, a later void one does not.
    if (grey_source) w.grey_values[at] = decided.grey_source[k];
    float* px = grid.pixel(col, r).data();
    for (std::size_t j = 0; j < m; ++j) {
      px[j] = f[j];
      fractions_ok &= static_cast<int>(f[j] >= fraction_lo) & static_cast<int>(f[j] <= fraction_hi);
    }
    fractions_ok &= static_cast<int>(sum <= fraction_hi);
  }
  // The grid is checked as it is written, not again by the dithering (dither_checked_grid).
  if (!fractions_ok)
    for (int col : row.cols) grid.check_pixel(col, r, dither.fraction_tolerance);
}

// Voxels per material and inside pixels over the written spans (outside them every pixel is
// outside and void), and pixels per owning cell.
void Slicer::Impl::count_labels(LayerResult& result, LayerWork& w, bool owner_out) const {
  LayerStats& st = w.stats;
  const int m = scene.num_materials();
  const InsideMask& inside = w.buffers->inside;
  st.voxels_per_material.assign(static_cast<std::size_t>(m), 0);
  std::vector<std::int64_t> per_label(static_cast<std::size_t>(m) + 1, 0);
  for (int r = 0; r < layout.height_px; ++r) {
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
  st.pixels_per_cell.assign(decision->cells().size(), 0);
  if (w.several_cells) {
    for (int o : w.owner)
      if (o >= 0) ++st.pixels_per_cell[static_cast<std::size_t>(o)];
  } else {
    if (!decision->cells().empty()) st.pixels_per_cell[0] = st.pixels_inside;
    if (owner_out) {
      w.owner.resize(static_cast<std::size_t>(st.pixels_total));
      std::transform(inside.values().begin(), inside.values().end(), w.owner.begin(),
                     [](std::uint8_t in) { return in != 0 ? 0 : -1; });
    }
  }
  if (owner_out) result.owner = std::move(w.owner);
}

}  // namespace trivox
