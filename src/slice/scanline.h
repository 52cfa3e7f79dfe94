// Scan conversion of a cell's outline into the pixels worth inverting, row by row.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "trivox/math.h"
#include "trivox/mesh/sliced_mesh.h"
#include "trivox/slice/layout.h"

namespace trivox::detail {

// The x range (lo, hi) of segment `s` clipped to the horizontal strip yc - half_height <= y <=
// yc + half_height (a horizontal segment's whole range; a segment that misses the strip gives
// its end nearest to it): where a segment's band meets a row.
std::pair<double, double> x_range_in_strip(const Segment2& s, double yc, double half_height);

// Inclusive column ranges per row.
using RowSpans = std::vector<std::vector<std::pair<int, int>>>;

// The candidate pixels of one layer: centres inside the outline by the even-odd rule, widened
// by `margin_mm`, plus every centre within `margin_mm` of an outline segment, so that a
// pixel whose centre lies in the cell is a candidate whenever the outline is within
// `margin_mm` of the true boundary. Rows with an odd number of crossings (a numerically
// open outline) fall back to the whole span between their first and last crossing.
// With `interior`, also the pixels the outline decides inside by itself, from the same
// crossings: centres inside by the even-odd rule and not within `margin_mm` of any segment,
// so that each lies in the cell whenever the outline is within `margin_mm` of the true
// boundary (none in a row with an odd number of crossings).
void candidate_spans(const std::vector<Segment2>& segments, const SliceLayout& layout, double margin_mm, RowSpans& rows,
                     RowSpans* interior = nullptr);

// Adds to `rows` every pixel whose centre lies within `margin_mm` (in x and in y) of the part
// of a triangle inside the slab z0 <= z <= z1, projected on the layer: with the even-odd
// interior of the cut at the slab's middle (candidate_spans), every centre within the slab's
// half height and `margin_mm` of a surface is covered, however flat the surface lies.
void add_slab_spans(const std::vector<std::array<Vec3, 3>>& triangles, double z0, double z1, const SliceLayout& layout,
                    double margin_mm, RowSpans& rows);
// Sorts each row's spans and merges overlapping and touching ones.
void merge_spans(RowSpans& rows);
// Keeps in `rows` only the pixels also in `mask` (both merged).
void intersect_spans(RowSpans& rows, const RowSpans& mask);
// Removes from `rows` the pixels in `mask` (both merged).
void subtract_spans(RowSpans& rows, const RowSpans& mask);

// The crossings of every row's centre line with a cut shell (trivox/trim/detail/shell_mesh.h), by
// the rule of crosses_row (trivox/mesh/sliced_mesh.h), as ShellMesh::contains counts them, sorted per row: pixel (col,
// row) is inside the shell when an odd number of its row's crossings lie beyond x_of_col(col).
void shell_row_crossings(const std::vector<Segment2>& segments, const SliceLayout& layout,
                         std::vector<std::vector<double>>& rows);

// The same for a shell decided by its winding number (ShellMesh::winding): each row's
// crossings sorted, and beside them the windings beyond each, windings[r][i] the sum of
// crossing_winding over crossings i, i + 1, ... of row r (one entry more, 0, past the last).
void shell_row_windings(const std::vector<Segment2>& segments, const std::vector<int>& directions,
                        const SliceLayout& layout, std::vector<std::vector<double>>& rows,
                        std::vector<std::vector<int>>& windings);
// The winding of a row's crossings beyond abscissa x (the w of ShellMesh::winding_inside).
int winding_beyond(const std::vector<double>& xs, const std::vector<int>& windings, double x) noexcept;

// The first column whose pixel centre lies at or right of x (width_px when none): exact,
// by comparing the centres themselves (SliceLayout::x_of_col), as the tests per pixel do.
int first_col_at_or_after(const SliceLayout& layout, double x) noexcept;
// The columns of a row where a shell clause holds, as sorted disjoint spans [c0, c1] in
// `runs`: the pixel centres inside by the row's sorted crossings `xs` (even-odd, or with
// `windings`, shell_row_windings' windings of the row, winding at least 1), or outside when
// `inside` is false. Each column's answer is that of inside_crossings (or winding_beyond >=
// 1) at its centre, decided once per stretch between two crossings instead of per pixel.
void crossing_runs(const std::vector<double>& xs, const std::vector<int>* windings, bool inside,
                   const SliceLayout& layout, std::vector<std::pair<int, int>>& runs);
// The spans of `a` that lie in spans of `b` (both sorted and disjoint), in `out`.
void intersect_row(const std::vector<std::pair<int, int>>& a, const std::vector<std::pair<int, int>>& b,
                   std::vector<std::pair<int, int>>& out);

// Whether abscissa x is inside by the even-odd rule over a row's sorted crossings.
bool inside_crossings(const std::vector<double>& xs, double x) noexcept;

}  // namespace trivox::detail
