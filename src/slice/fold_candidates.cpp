#include "fold_candidates.h"

#include <algorithm>
#include <cmath>

#include "trivox/spline/refine.h"

namespace trivox::detail {

FoldCandidates::FoldCandidates(const Volume& volume) {
  for (const TensorSpline& piece : bezier_patches(volume.spline())) boxes_.push_back(piece.control_box());
}

void FoldCandidates::spans(const SliceLayout& L, double z_mm, double margin_mm, RowSpans& rows) const {
  rows.assign(static_cast<std::size_t>(L.height_px), {});
  // Column and row ranges are clamped as doubles first: a box far outside the bitmap must
  // not overflow an int.
  auto clamped = [](double v, int hi) { return static_cast<int>(std::clamp(v, -1.0, static_cast<double>(hi) + 1.0)); };
  for (const Box3& b : boxes_) {
    if (z_mm < b.lo.z - margin_mm || z_mm > b.hi.z + margin_mm) continue;
    const int c0 = std::max(0, clamped(std::ceil(L.col_of_x(b.lo.x - margin_mm)), L.width_px));
    const int c1 = std::min(L.width_px - 1, clamped(std::floor(L.col_of_x(b.hi.x + margin_mm)), L.width_px));
    const int r0 = std::max(0, clamped(std::ceil(L.row_of_y(b.hi.y + margin_mm)), L.height_px));
    const int r1 = std::min(L.height_px - 1, clamped(std::floor(L.row_of_y(b.lo.y - margin_mm)), L.height_px));
    if (c0 > c1) continue;
    for (int r = r0; r <= r1; ++r) rows[static_cast<std::size_t>(r)].push_back({c0, c1});
  }
  merge_spans(rows);
}

}  // namespace trivox::detail
