// Scan conversion of outlines and cut shells: crossings of segments that end exactly on a
// row's centre line.
#include <cmath>

#include <gtest/gtest.h>

#include "slice/scanline.h"

namespace trivox {
namespace {

// A row whose centre, converted back to a fractional row, rounds to just above the row
// (row_of_y is not the exact inverse of y_of_row): the case where a segment ending on that
// centre line was once not tested against the row.
int row_rounding_up(const SliceLayout& L) {
  for (int r = 0; r < L.height_px; ++r)
    if (std::ceil(L.row_of_y(L.y_of_row(r))) > r) return r;
  return -1;
}

TEST(Scanline, SegmentsEndingOnARowCentreKeepTheirCrossing) {
  SliceLayout L;
  L.x0_mm = -5;
  L.y_top_mm = 7;
  L.pitch_x_mm = 0.0423;
  L.pitch_y_mm = 0.0847;
  L.layer_mm = 0.03;
  L.width_px = 240;
  L.height_px = 400;
  L.num_layers = 1;
  const int r = row_rounding_up(L);
  ASSERT_GE(r, 1) << "no row of this layout rounds up; the test needs one";
  const double yc = L.y_of_row(r);
  // A closed outline A B C D whose vertex B lies on the centre line of row r: the path climbs
  // through B, so row r crosses it once there (A B ends on the line, B C starts on it; by the
  // rule "on the line counts as above" only A B crosses) and once on D A.
  const double ax = 0, ay = yc - 1, bx = 1, by = yc, cx = 0, cy = yc + 1, dx = -1, dy = yc + 0.3;
  const std::vector<Segment2> shell = {{ax, ay, bx, by}, {bx, by, cx, cy}, {cx, cy, dx, dy}, {dx, dy, ax, ay}};
  std::vector<std::vector<double>> rows;
  detail::shell_row_crossings(shell, L, rows);
  ASSERT_EQ(rows[static_cast<std::size_t>(r)].size(), 2u);
  EXPECT_EQ(rows[static_cast<std::size_t>(r)][1], bx);
  // Inside the outline on that row, outside beyond it.
  EXPECT_TRUE(detail::inside_crossings(rows[static_cast<std::size_t>(r)], 0.0));
  EXPECT_FALSE(detail::inside_crossings(rows[static_cast<std::size_t>(r)], 2.0));

  // The cells' outlines: the same crossing fills the span between them (with no margin),
  // not the fallback of an odd row.
  std::vector<Segment2> outline;
  for (const Segment2& s : shell) outline.push_back({s.x0, s.y0, s.x1, s.y1});
  detail::RowSpans spans;
  detail::candidate_spans(outline, L, 0.0, spans);
  const auto& row = spans[static_cast<std::size_t>(r)];
  ASSERT_EQ(row.size(), 1u);
  EXPECT_NEAR(L.x_of_col(row[0].second), bx, L.pitch_x_mm);
}

}  // namespace
}  // namespace trivox
