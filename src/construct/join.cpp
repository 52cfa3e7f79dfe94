// Joining a grid of surfaces into one: compatible spaces per column (u) and per row (v),
// then the control nets concatenated with C0 joints (see join.h).
#include "trivox/construct/join.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "construct/construct_util.h"
#include "trivox/error.h"

namespace trivox {

namespace {

// The knot vector of `parts` pieces laid end to end: piece c's clamped knots on [0, 1]
// shifted to [c, c + 1], each joint kept with multiplicity order - 1 (C0).
KnotVector joined_knots(const std::vector<KnotVector>& pieces) {
  const int order = pieces.front().order();
  std::vector<double> knots(static_cast<std::size_t>(order), 0.0);
  for (std::size_t c = 0; c < pieces.size(); ++c) {
    const auto k = pieces[c].knots();
    for (std::size_t i = static_cast<std::size_t>(order); i + static_cast<std::size_t>(order) < k.size(); ++i)
      knots.push_back(k[i] + static_cast<double>(c));
    const double end = static_cast<double>(c + 1);
    knots.insert(knots.end(), static_cast<std::size_t>(c + 1 < pieces.size() ? order - 1 : order), end);
  }
  return KnotVector(order, std::move(knots));
}

}  // namespace

TensorSpline join_surfaces(const std::vector<std::vector<TensorSpline>>& grid, const JoinParams& params) {
  if (grid.empty() || grid.front().empty()) throw ModelError("a grid of surfaces to join is empty");
  const std::size_t rows = grid.size(), cols = grid.front().size();
  std::vector<std::vector<TensorSpline>> g(rows);
  bool rational = false;
  int order[2] = {1, 1};
  Box3 box;
  for (std::size_t r = 0; r < rows; ++r) {
    if (grid[r].size() != cols)
      throw ModelError(
          fmt::format("row {} of the grid of surfaces has {} patches, row 0 has {}", r, grid[r].size(), cols));
    for (std::size_t c = 0; c < cols; ++c) {
      g[r].push_back(detail::checked_surface(grid[r][c], fmt::format("patch (row {}, column {})", r, c)));
      const TensorSpline& s = g[r].back();
      rational = rational || s.is_rational();
      for (int d = 0; d < 2; ++d) order[d] = std::max(order[d], s.knots(d).order());
      box.expand(s.control_box());
    }
  }
  for (auto& row : g)
    for (TensorSpline& s : row)
      if (rational && !s.is_rational())
        s = TensorSpline(s.all_knots(), 3, std::vector<double>(s.points().begin(), s.points().end()),
                         std::vector<double>(static_cast<std::size_t>(s.total_ctrl()), 1.0));
  // One u space per column, one v space per row, all of the same orders.
  for (std::size_t c = 0; c < cols; ++c) {
    std::vector<detail::SplineDir> column;
    for (std::size_t r = 0; r < rows; ++r) column.push_back({&g[r][c], 0});
    detail::make_compatible(column, order[0]);
  }
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<detail::SplineDir> row;
    for (std::size_t c = 0; c < cols; ++c) row.push_back({&g[r][c], 1});
    detail::make_compatible(row, order[1]);
  }

  const double tol = params.edge_tolerance_relative * std::max(box.diagonal(), 1e-300);
  const auto check = [&](const TensorSpline& a, int ia, int ja, const TensorSpline& b, int ib, int jb,
                         std::string_view what) {
    const auto pa = a.point(ia, ja), pb = b.point(ib, jb);
    const double d = norm(detail::to_vec3(pa) - detail::to_vec3(pb));
    const double wa = a.weight(ia, ja), wb = b.weight(ib, jb);
    if (d > tol || std::abs(wa - wb) > 1e-9 * std::max(wa, wb))
      throw ModelError(
          fmt::format("{}: control points differ by {:.6g}{} (each patch's u must run along its row "
                      "and v along its column, in the same direction as its neighbours')",
                      what, d, std::abs(wa - wb) > 1e-9 * std::max(wa, wb) ? " and in weight" : ""));
  };
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c) {
      const TensorSpline& s = g[r][c];
      if (c + 1 < cols) {
        const TensorSpline& t = g[r][c + 1];
        for (int j = 0; j < s.num_ctrl(1); ++j)
          check(s, s.num_ctrl(0) - 1, j, t, 0, j,
                fmt::format("patches (row {}, column {}) and (row {}, column {}) do not share their edge u = 1 / u = 0",
                            r, c, r, c + 1));
      }
      if (r + 1 < rows) {
        const TensorSpline& t = g[r + 1][c];
        for (int i = 0; i < s.num_ctrl(0); ++i)
          check(s, i, s.num_ctrl(1) - 1, t, i, 0,
                fmt::format("patches (row {}, column {}) and (row {}, column {}) do not share their edge v = 1 / v = 0",
                            r, c, r + 1, c));
      }
    }

  std::vector<KnotVector> ku, kv;
  for (std::size_t c = 0; c < cols; ++c) ku.push_back(g[0][c].knots(0));
  for (std::size_t r = 0; r < rows; ++r) kv.push_back(g[r][0].knots(1));
  KnotVector u = joined_knots(ku), v = joined_knots(kv);
  std::vector<double> pts, wts;
  pts.reserve(static_cast<std::size_t>(u.num_ctrl() * v.num_ctrl() * 3));
  for (std::size_t r = 0; r < rows; ++r)
    for (int j = r == 0 ? 0 : 1; j < g[r][0].num_ctrl(1); ++j)
      for (std::size_t c = 0; c < cols; ++c) {
        const TensorSpline& s = g[r][c];
        for (int i = c == 0 ? 0 : 1; i < s.num_ctrl(0); ++i) {
          const auto p = s.point(i, j);
          pts.insert(pts.end(), p.begin(), p.end());
          if (rational) wts.push_back(s.weight(i, j));
        }
      }
  return TensorSpline({std::move(u), std::move(v)}, 3, std::move(pts), std::move(wts));
}

}  // namespace trivox
