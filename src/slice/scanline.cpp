#include "scanline.h"

#include <algorithm>
#include <cmath>

namespace trivox::detail {

namespace {

// Rows whose centre y lies in [ylo, yhi], clamped to the image.
std::pair<int, int> rows_between(const SliceLayout& L, double ylo, double yhi) {
  const int r0 = std::max(0, static_cast<int>(std::ceil(L.row_of_y(yhi))));
  const int r1 = std::min(L.height_px - 1, static_cast<int>(std::floor(L.row_of_y(ylo))));
  return {r0, r1};
}

// The same, one row wider on each side, for crossing tests that decide themselves: row_of_y
// is not the exact inverse of y_of_row, so a segment ending exactly on a row's centre line
// (a vertex of a mesh in the plane y = y_c) could otherwise lose that row, and with it a
// crossing its neighbour does not count, flipping the parity of the rest of the row.
std::pair<int, int> rows_near(const SliceLayout& L, double ylo, double yhi) {
  const auto [r0, r1] = rows_between(L, ylo, yhi);
  return {std::max(0, r0 - 1), std::min(L.height_px - 1, r1 + 1)};
}

void add_span(RowSpans& rows, const SliceLayout& L, int row, double xlo, double xhi) {
  const int c0 = std::max(0, static_cast<int>(std::ceil(L.col_of_x(xlo))));
  const int c1 = std::min(L.width_px - 1, static_cast<int>(std::floor(L.col_of_x(xhi))));
  if (c0 <= c1) rows[static_cast<std::size_t>(row)].push_back({c0, c1});
}

// Each row's crossings of the outline with its centre line, sorted (the even-odd interior
// lies between crossings 0 and 1, 2 and 3, ...), and the band of centres within m of a
// segment (unmerged spans).
void crossings_and_band(const std::vector<Segment2>& segments, const SliceLayout& L, double m,
                        std::vector<std::vector<double>>& crossings, RowSpans& band) {
  crossings.assign(static_cast<std::size_t>(L.height_px), {});
  band.assign(static_cast<std::size_t>(L.height_px), {});
  for (const Segment2& s : segments) {
    // Crossings with the row centre lines, by the rule "y >= y_c counts as above" applied
    // to each endpoint, so two segments sharing an endpoint never both count it.
    const auto [r0, r1] = rows_near(L, std::min(s.y0, s.y1), std::max(s.y0, s.y1));
    for (int r = r0; r <= r1; ++r) {
      const double yc = L.y_of_row(r);
      if ((s.y0 >= yc) == (s.y1 >= yc)) continue;
      crossings[static_cast<std::size_t>(r)].push_back(s.x0 + (yc - s.y0) / (s.y1 - s.y0) * (s.x1 - s.x0));
    }
    // The band of centres within m of the segment: clip it to each nearby row's strip.
    const auto [b0, b1] = rows_between(L, std::min(s.y0, s.y1) - m, std::max(s.y0, s.y1) + m);
    for (int r = b0; r <= b1; ++r) {
      const auto [xlo, xhi] = x_range_in_strip(s, L.y_of_row(r), m);
      add_span(band, L, r, xlo - m, xhi + m);
    }
  }
  for (auto& xs : crossings) std::sort(xs.begin(), xs.end());
}

}  // namespace

std::pair<double, double> x_range_in_strip(const Segment2& s, double yc, double half_height) {
  if (s.y0 == s.y1) return {std::min(s.x0, s.x1), std::max(s.x0, s.x1)};
  double t0 = (yc - half_height - s.y0) / (s.y1 - s.y0), t1 = (yc + half_height - s.y0) / (s.y1 - s.y0);
  if (t0 > t1) std::swap(t0, t1);
  t0 = std::clamp(t0, 0.0, 1.0);
  t1 = std::clamp(t1, 0.0, 1.0);
  const double xa = s.x0 + t0 * (s.x1 - s.x0), xb = s.x0 + t1 * (s.x1 - s.x0);
  return {std::min(xa, xb), std::max(xa, xb)};
}

void candidate_spans(const std::vector<Segment2>& segments, const SliceLayout& L, double m, RowSpans& rows,
                     RowSpans* interior) {
  std::vector<std::vector<double>> crossings;
  crossings_and_band(segments, L, m, crossings, rows);
  if (interior != nullptr) {
    // The even-odd inside, less the band (not yet widened by the intervals below).
    RowSpans band = rows;
    merge_spans(band);
    interior->assign(static_cast<std::size_t>(L.height_px), {});
    for (int r = 0; r < L.height_px; ++r) {
      const auto& xs = crossings[static_cast<std::size_t>(r)];
      if (xs.size() % 2 == 1) continue;  // a numerically open outline decides nothing
      for (std::size_t i = 0; i + 1 < xs.size(); i += 2) add_span(*interior, L, r, xs[i], xs[i + 1]);
    }
    subtract_spans(*interior, band);
  }
  for (int r = 0; r < L.height_px; ++r) {
    const auto& xs = crossings[static_cast<std::size_t>(r)];
    if (xs.size() % 2 == 1) {
      add_span(rows, L, r, xs.front() - m, xs.back() + m);
    } else {
      for (std::size_t i = 0; i + 1 < xs.size(); i += 2) add_span(rows, L, r, xs[i] - m, xs[i + 1] + m);
    }
  }
  merge_spans(rows);
}

void merge_spans(RowSpans& rows) {
  for (auto& spans : rows) {
    std::sort(spans.begin(), spans.end());
    std::vector<std::pair<int, int>> merged;
    for (const auto& sp : spans) {
      if (!merged.empty() && sp.first <= merged.back().second + 1)
        merged.back().second = std::max(merged.back().second, sp.second);
      else
        merged.push_back(sp);
    }
    spans = std::move(merged);
  }
}

void subtract_spans(RowSpans& rows, const RowSpans& mask) {
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (r >= mask.size() || mask[r].empty()) continue;
    const auto& b = mask[r];
    std::vector<std::pair<int, int>> out;
    std::size_t j = 0;
    for (auto [a0, a1] : rows[r]) {
      while (j < b.size() && b[j].second < a0) ++j;
      for (std::size_t k = j; k < b.size() && b[k].first <= a1 && a0 <= a1; ++k) {
        if (b[k].first > a0) out.push_back({a0, b[k].first - 1});
        a0 = std::max(a0, b[k].second + 1);
      }
      if (a0 <= a1) out.push_back({a0, a1});
    }
    rows[r] = std::move(out);
  }
}

void intersect_spans(RowSpans& rows, const RowSpans& mask) {
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto& b = r < mask.size() ? mask[r] : std::vector<std::pair<int, int>>{};
    std::vector<std::pair<int, int>> out;
    std::size_t j = 0;
    for (const auto& [a0, a1] : rows[r]) {
      while (j < b.size() && b[j].second < a0) ++j;
      for (std::size_t k = j; k < b.size() && b[k].first <= a1; ++k) {
        const int lo = std::max(a0, b[k].first), hi = std::min(a1, b[k].second);
        if (lo <= hi) out.push_back({lo, hi});
      }
    }
    rows[r] = std::move(out);
  }
}

namespace {

// Sutherland-Hodgman: the part of a convex polygon where f(p) >= 0, f affine.
template <class P, class F>
std::vector<P> clip(const std::vector<P>& poly, F f) {
  std::vector<P> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const P& a = poly[i];
    const P& b = poly[(i + 1) % poly.size()];
    const double fa = f(a), fb = f(b);
    if (fa >= 0) out.push_back(a);
    if ((fa >= 0) != (fb >= 0)) out.push_back(a + (fa / (fa - fb)) * (b - a));
  }
  return out;
}

}  // namespace

void add_slab_spans(const std::vector<std::array<Vec3, 3>>& triangles, double z0, double z1, const SliceLayout& L,
                    double m, RowSpans& rows) {
  rows.resize(static_cast<std::size_t>(L.height_px));
  for (const auto& t : triangles) {
    std::vector<Vec3> poly(t.begin(), t.end());
    poly = clip(poly, [z0](const Vec3& p) { return p.z - z0; });
    poly = clip(poly, [z1](const Vec3& p) { return z1 - p.z; });
    if (poly.empty()) continue;
    double ylo = poly[0].y, yhi = poly[0].y;
    for (const Vec3& p : poly) {
      ylo = std::min(ylo, p.y);
      yhi = std::max(yhi, p.y);
    }
    const auto [r0, r1] = rows_between(L, ylo - m, yhi + m);
    for (int r = r0; r <= r1; ++r) {
      const double yc = L.y_of_row(r);
      std::vector<Vec3> strip = clip(poly, [&](const Vec3& p) { return p.y - (yc - m); });
      strip = clip(strip, [&](const Vec3& p) { return (yc + m) - p.y; });
      if (strip.empty()) {
        // A polygon thinner than rounding between the strip's lines: its own extent.
        if (ylo > yc + m || yhi < yc - m) continue;
        strip = poly;
      }
      double xlo = strip[0].x, xhi = strip[0].x;
      for (const Vec3& p : strip) {
        xlo = std::min(xlo, p.x);
        xhi = std::max(xhi, p.x);
      }
      add_span(rows, L, r, xlo - m, xhi + m);
    }
  }
}

void shell_row_crossings(const std::vector<Segment2>& segments, const SliceLayout& L,
                         std::vector<std::vector<double>>& rows) {
  rows.resize(static_cast<std::size_t>(L.height_px));
  for (auto& r : rows) r.clear();
  for (const Segment2& s : segments) {
    const auto [r0, r1] = rows_near(L, std::min(s.y0, s.y1), std::max(s.y0, s.y1));
    double x;
    for (int r = r0; r <= r1; ++r)
      if (crosses_row(s, L.y_of_row(r), x)) rows[static_cast<std::size_t>(r)].push_back(x);
  }
  for (auto& r : rows) std::sort(r.begin(), r.end());
}

void shell_row_windings(const std::vector<Segment2>& segments, const std::vector<int>& directions, const SliceLayout& L,
                        std::vector<std::vector<double>>& rows, std::vector<std::vector<int>>& windings) {
  std::vector<std::vector<std::pair<double, int>>> found(static_cast<std::size_t>(L.height_px));
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const Segment2& s = segments[k];
    const auto [r0, r1] = rows_near(L, std::min(s.y0, s.y1), std::max(s.y0, s.y1));
    double x;
    for (int r = r0; r <= r1; ++r)
      if (crosses_row(s, L.y_of_row(r), x))
        found[static_cast<std::size_t>(r)].push_back({x, crossing_winding(s, directions[k])});
  }
  rows.resize(static_cast<std::size_t>(L.height_px));
  windings.resize(static_cast<std::size_t>(L.height_px));
  for (std::size_t r = 0; r < found.size(); ++r) {
    auto& f = found[r];
    std::sort(f.begin(), f.end());
    rows[r].resize(f.size());
    windings[r].assign(f.size() + 1, 0);
    for (std::size_t i = f.size(); i-- > 0;) {
      rows[r][i] = f[i].first;
      windings[r][i] = windings[r][i + 1] + f[i].second;
    }
  }
}

int winding_beyond(const std::vector<double>& xs, const std::vector<int>& windings, double x) noexcept {
  return windings[static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin())];
}

int first_col_at_or_after(const SliceLayout& L, double x) noexcept {
  if (L.width_px <= 0 || !(x > L.x_of_col(0))) return 0;
  if (!(x <= L.x_of_col(L.width_px - 1))) return L.width_px;
  // An estimate, then the centres themselves decide: x_of_col increases with the column.
  int c = std::clamp(static_cast<int>(std::ceil(L.col_of_x(x))), 1, L.width_px - 1);
  while (c > 0 && L.x_of_col(c - 1) >= x) --c;
  while (c < L.width_px && L.x_of_col(c) < x) ++c;
  return c;
}

void crossing_runs(const std::vector<double>& xs, const std::vector<int>* windings, bool inside, const SliceLayout& L,
                   std::vector<std::pair<int, int>>& runs) {
  runs.clear();
  // Centres x with xs[i - 1] <= x < xs[i] have i crossings at or left of them (upper_bound)
  // and xs.size() - i beyond: the same answer all along, from column first_col(xs[i - 1]) to
  // the column before first_col(xs[i]).
  const std::size_t n = xs.size();
  int c0 = 0;
  for (std::size_t i = 0; i <= n; ++i) {
    const int c1 = i < n ? first_col_at_or_after(L, xs[i]) : L.width_px;
    const bool in = windings != nullptr ? (*windings)[i] >= 1 : (n - i) % 2 == 1;
    if (in == inside && c0 < c1) {
      if (!runs.empty() && runs.back().second == c0 - 1)
        runs.back().second = c1 - 1;
      else
        runs.push_back({c0, c1 - 1});
    }
    c0 = std::max(c0, c1);
    if (c0 >= L.width_px) break;
  }
}

void intersect_row(const std::vector<std::pair<int, int>>& a, const std::vector<std::pair<int, int>>& b,
                   std::vector<std::pair<int, int>>& out) {
  out.clear();
  std::size_t j = 0;
  for (const auto& [a0, a1] : a) {
    while (j < b.size() && b[j].second < a0) ++j;
    for (std::size_t k = j; k < b.size() && b[k].first <= a1; ++k) {
      const int lo = std::max(a0, b[k].first), hi = std::min(a1, b[k].second);
      if (lo <= hi) out.push_back({lo, hi});
    }
  }
}

bool inside_crossings(const std::vector<double>& xs, double x) noexcept {
  // Crossings beyond x, as ShellMesh::contains counts them.
  const auto beyond = xs.end() - std::upper_bound(xs.begin(), xs.end(), x);
  return beyond % 2 == 1;
}

}  // namespace trivox::detail
