// Scan conversion of outlines and cut shells: crossings of segments that end exactly on a
// row's centre line.
#include <cmath>
#include <random>

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

// The spans of a row's crossings (crossing_runs, which the slicer's narrowing to shell
// clauses uses) against the test per pixel (inside_crossings, winding_beyond), column by
// column: crossings exactly on pixel centres, a hair either side of them, repeated, beyond
// either end of the row, and at infinities; even-odd, windings, and both sides.
TEST(Scanline, CrossingRunsAgreeWithThePixelTests) {
  SliceLayout L;
  L.x0_mm = -3.7;
  L.y_top_mm = 1;
  L.pitch_x_mm = 0.0423;
  L.pitch_y_mm = 0.0847;
  L.layer_mm = 0.03;
  L.width_px = 97;
  L.height_px = 1;
  L.num_layers = 1;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> col(-5, L.width_px + 5), kind(0, 5), sign(0, 1);
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<double> xs;
    const int n = trial % 9;
    for (int i = 0; i < n; ++i) {
      const double c = L.x_of_col(col(rng));
      switch (kind(rng)) {
        case 0: xs.push_back(c); break;
        case 1: xs.push_back(std::nextafter(c, HUGE_VAL)); break;
        case 2: xs.push_back(std::nextafter(c, -HUGE_VAL)); break;
        case 3: xs.push_back(c + 0.3 * L.pitch_x_mm); break;
        case 4: xs.push_back(i % 2 ? HUGE_VAL : -HUGE_VAL); break;
        default: xs.push_back(xs.empty() ? c : xs.back()); break;  // a repeated crossing
      }
    }
    std::sort(xs.begin(), xs.end());
    std::vector<int> windings(xs.size() + 1, 0);
    for (std::size_t i = xs.size(); i-- > 0;) windings[i] = windings[i + 1] + (sign(rng) ? 1 : -1);
    for (const bool use_windings : {false, true})
      for (const bool inside : {false, true}) {
        std::vector<std::pair<int, int>> runs;
        detail::crossing_runs(xs, use_windings ? &windings : nullptr, inside, L, runs);
        std::vector<char> got(static_cast<std::size_t>(L.width_px), 0);
        for (std::size_t k = 0; k < runs.size(); ++k) {
          ASSERT_LE(runs[k].first, runs[k].second);
          if (k > 0) {
            ASSERT_LT(runs[k - 1].second + 1, runs[k].first);  // sorted, disjoint, merged
          }
          for (int c = runs[k].first; c <= runs[k].second; ++c) got[static_cast<std::size_t>(c)] = 1;
        }
        for (int c = 0; c < L.width_px; ++c) {
          const double x = L.x_of_col(c);
          const bool in = use_windings ? detail::winding_beyond(xs, windings, x) >= 1 : detail::inside_crossings(xs, x);
          ASSERT_EQ(got[static_cast<std::size_t>(c)] != 0, in == inside)
              << "trial " << trial << " column " << c << (use_windings ? " windings" : " even-odd");
        }
      }
  }
}

}  // namespace
}  // namespace trivox
