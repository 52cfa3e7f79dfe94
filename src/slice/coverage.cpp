#include "coverage.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_preparation.h"
#include "scanline.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox::detail {

GreyImage grey_from_grid(const MaterialGrid& grid, const std::vector<std::pair<int, int>>& written,
                         const GreyscaleDef& greyscale, std::span<const float> values) {
  GreyImage grey(grid.width_px(), grid.height_px(), 0);
  const int m = grid.num_materials();
  for (int r = 0; r < grid.height_px(); ++r) {
    const auto [first, last] = written[static_cast<std::size_t>(r)];
    for (int col = first; col <= last; ++col) {
      const std::span<const float> f = grid.pixel(col, r);
      float sum = 0.0f;
      for (int j = 0; j < m; ++j) sum += f[static_cast<std::size_t>(j)];
      if (!(sum > 0.0f)) continue;
      const double value =
          greyscale.material >= 0
              ? static_cast<double>(f[static_cast<std::size_t>(greyscale.material)])
              : static_cast<double>(values[static_cast<std::size_t>(r) * static_cast<std::size_t>(grid.width_px()) +
                                           static_cast<std::size_t>(col)]);
      grey.at(col, r) = greyscale.curve.level(value);
    }
  }
  return grey;
}

std::unique_ptr<LayerDecision> coverage_decision(const Scene& scene, const SliceParams& params,
                                                 const SliceLayout& grid) {
  LayerDecision::Setup setup;
  // As the slicer's outlines are to the pixels (an eighth of the finest pitch), so these are
  // to the points of `grid`.
  setup.outline_tolerance_mm = 0.125 * std::min({grid.pitch_x_mm, grid.pitch_y_mm, grid.layer_mm});
  setup.shell_tolerance_mm = setup.outline_tolerance_mm;
  auto decision = std::make_unique<LayerDecision>(scene, params, setup);
  // Within a fixed budget (as the slicer's outline meshes are within theirs); a mesh the
  // budget cuts short is accepted here: a sub-sample it misjudges near the edge moves an
  // edge pixel's grey level by one sub-sample.
  decision->build_meshes(std::vector<std::int64_t>(decision->trivariates().size(), std::int64_t{1} << 22));
  decision->set_layout(grid);
  return decision;
}

EdgeCoverage::EdgeCoverage(const Scene& scene, const SliceParams& params, const SliceLayout& layout)
    : scene_(scene), layout_(layout) {
  if (!scene.greyscale) throw Error("edge coverage needs a scene with a greyscale block");
  k_ = scene.greyscale->antialiasing;
  if (k_ < 2 || k_ > 8) throw Error(fmt::format("edge coverage: {} x {} sub-samples; k is 2 to 8", k_, k_));
  fine_ = layout;
  fine_.pitch_x_mm = layout.pitch_x_mm / k_;
  fine_.pitch_y_mm = layout.pitch_y_mm / k_;
  fine_.width_px = layout.width_px * k_;
  fine_.height_px = layout.height_px * k_;
  decision_ = coverage_decision(scene, params, fine_);
  tolerance_mm_ = decision_->setup().outline_tolerance_mm;
}

EdgeCoverage::~EdgeCoverage() = default;

namespace {

// Marks every pixel of `L` whose square, widened by `margin` on each side, meets segment s.
void mark_band(const Segment2& s, const SliceLayout& L, double margin, std::vector<std::uint8_t>& band) {
  const double hx = 0.5 * L.pitch_x_mm + margin, hy = 0.5 * L.pitch_y_mm + margin;
  const double ylo = std::min(s.y0, s.y1), yhi = std::max(s.y0, s.y1);
  const int r0 = std::max(0, static_cast<int>(std::ceil(L.row_of_y(yhi + hy))));
  const int r1 = std::min(L.height_px - 1, static_cast<int>(std::floor(L.row_of_y(ylo - hy))));
  for (int r = r0; r <= r1; ++r) {
    // The part of the segment within the row's widened strip [yc - hy, yc + hy].
    const auto [xa, xb] = x_range_in_strip(s, L.y_of_row(r), hy);
    const int c0 = std::max(0, static_cast<int>(std::ceil(L.col_of_x(xa - hx))));
    const int c1 = std::min(L.width_px - 1, static_cast<int>(std::floor(L.col_of_x(xb + hx))));
    for (int c = c0; c <= c1; ++c)
      band[static_cast<std::size_t>(r) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(c)] = 1;
  }
}

}  // namespace

std::int64_t EdgeCoverage::antialias(int layer, GreyImage& grey) const {
  const SliceLayout& L = layout_;
  const SliceLayout& F = fine_;
  const double z = L.z_of_layer(layer);
  const double margin = 2.0 * tolerance_mm_;
  const auto width = static_cast<std::size_t>(L.width_px);

  // 1. The edge pixels: near the cut of any outline.
  std::vector<std::uint8_t> in_band(width * static_cast<std::size_t>(L.height_px), 0);
  std::vector<Segment2> segments;
  for (const auto& tv : decision_->trivariates()) {
    tv->mesh.cut(z, segments);
    for (const Segment2& s : segments) mark_band(s, L, margin, in_band);
  }
  for (const auto& cd : decision_->cells())
    for (const auto& k : cd->clauses) {
      const ShellMesh* outline = k.shell_slot >= 0 ? k.mesh.get() : k.outline.get();
      if (outline == nullptr) continue;
      outline->mesh().cut(z, segments);
      for (const Segment2& s : segments) mark_band(s, L, margin, in_band);
    }
  std::vector<int> band_index(in_band.size(), -1);
  std::vector<std::pair<int, int>> band;  // (col, row), row-major
  for (int r = 0; r < L.height_px; ++r)
    for (int c = 0; c < L.width_px; ++c) {
      const std::size_t at = static_cast<std::size_t>(r) * width + static_cast<std::size_t>(c);
      if (!in_band[at]) continue;
      band_index[at] = static_cast<int>(band.size());
      band.push_back({c, r});
    }
  if (band.empty()) return 0;

  // 2. Their sub-samples, as spans of the fine grid.
  const int k = k_;
  RowSpans band_spans(static_cast<std::size_t>(F.height_px));
  for (int r = 0; r < L.height_px; ++r) {
    int c = 0;
    while (c < L.width_px) {
      if (!in_band[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(c)]) {
        ++c;
        continue;
      }
      int e = c;
      while (e + 1 < L.width_px && in_band[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(e + 1)]) ++e;
      for (int i = 0; i < k; ++i) band_spans[static_cast<std::size_t>(r * k + i)].push_back({c * k, e * k + k - 1});
      c = e + 1;
    }
  }

  // 3. The grey of every sub-sample (layer_decision.h): its owning cell's, 0 where no cell
  // gives material.
  const GreyscaleDef& g = *scene_.greyscale;
  const int m = scene_.num_materials();
  const auto kk = static_cast<std::size_t>(k) * static_cast<std::size_t>(k);
  DecidedPoints points;
  decide_points(
      *decision_, z, &band_spans, band.size() * kk, m,
      [&](int col, int r) {
        const auto b = static_cast<std::size_t>(
            band_index[static_cast<std::size_t>(r / k) * width + static_cast<std::size_t>(col / k)]);
        return b * kk + static_cast<std::size_t>(r % k) * static_cast<std::size_t>(k) +
               static_cast<std::size_t>(col % k);
      },
      points);
  std::vector<double> sub(band.size() * kk, 0.0);
  for (std::size_t at = 0; at < sub.size(); ++at) {
    if (!points.owner_gave_material[at]) continue;
    const double value =
        g.material >= 0 ? static_cast<double>(
                              points.fractions[at * static_cast<std::size_t>(m) + static_cast<std::size_t>(g.material)])
                        : static_cast<double>(points.grey_source[at]);
    sub[at] = g.curve.grey(value);
  }

  // 4. Each edge pixel: the mean of its sub-samples.
  for (std::size_t b = 0; b < band.size(); ++b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < kk; ++i) sum += sub[b * kk + i];
    grey.at(band[b].first, band[b].second) = GreyCalibration::round_level(sum / static_cast<double>(kk));
  }
  return static_cast<std::int64_t>(band.size());
}

}  // namespace trivox::detail
