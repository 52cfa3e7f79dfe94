// Scan conversion of a cell's outline into the pixels worth inverting, row by row.
#pragma once

#include <utility>
#include <vector>

#include "boundary_mesh.h"
#include "trivox/slice/layout.h"

namespace trivox::detail {

// Inclusive column ranges per row.
using RowSpans = std::vector<std::vector<std::pair<int, int>>>;

// The candidate pixels of one layer: centres inside the outline by the even-odd rule, widened
// by `margin_mm`, plus every centre within `margin_mm` of an outline segment, so that a
// pixel whose centre lies in the cell is a candidate whenever the outline is within
// `margin_mm` of the true boundary. Rows with an odd number of crossings (a numerically
// open outline) fall back to the whole span between their first and last crossing.
void candidate_spans(const std::vector<Segment2>& segments, const SliceLayout& layout, double margin_mm,
                     RowSpans& rows);

}  // namespace trivox::detail
