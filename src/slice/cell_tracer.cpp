#include "cell_tracer.h"

#include <algorithm>
#include <optional>

#include "inverse/newton.h"

namespace trivox::detail {

TraceCounters& TraceCounters::operator+=(const TraceCounters& o) noexcept {
  candidates += o.candidates;
  inside += o.inside;
  global_calls += o.global_calls;
  newton_evals += o.newton_evals;
  folded += o.folded;
  unresolved += o.unresolved;
  return *this;
}

CellTracer::CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px)
    : volume_(volume),
      solver_(solver),
      params_(params),
      cur_uvw_(static_cast<std::size_t>(width_px)),
      prev_uvw_(static_cast<std::size_t>(width_px)),
      cur_jac_(static_cast<std::size_t>(width_px)),
      prev_jac_(static_cast<std::size_t>(width_px)),
      cur_ok_(static_cast<std::size_t>(width_px), 0),
      prev_ok_(static_cast<std::size_t>(width_px), 0) {}

void CellTracer::begin_layer(double z_mm) {
  z_mm_ = z_mm;
  last_row_ = -2;
  std::fill(cur_ok_.begin(), cur_ok_.end(), 0);
  std::fill(prev_ok_.begin(), prev_ok_.end(), 0);
}

bool CellTracer::solve_pixel(Vec3 x, int col, Vec3& uvw, Vec3& seed_uvw) {
  const auto c = static_cast<std::size_t>(col);
  const int width = static_cast<int>(cur_ok_.size());
  const TracingStrategy s = params_.tracing;
  const bool predicts = s == TracingStrategy::kPredict || s == TracingStrategy::kFlood;
  // Along a row the inverse map is smooth: the quadratic through the last three solutions
  // predicts this one to O(pitch^3), usually within the residual tolerance, so a single
  // value-only evaluation settles the pixel. Otherwise Newton from the neighbours decides.
  // Where the map bends too fast for it (small or strongly curved cells), a failed guess
  // costs an evaluation, so after a failure the next few pixels go straight to Newton.
  if (predicts && col >= 3 && col >= retry_prediction_at_ && cur_ok_[c - 1] && cur_ok_[c - 2] && cur_ok_[c - 3]) {
    const Vec3 guess = 3.0 * (cur_uvw_[c - 1] - cur_uvw_[c - 2]) + cur_uvw_[c - 3];
    if (volume_.domain().contains(guess)) {
      ++counters_.newton_evals;
      const Vec3 residual = x - volume_.evaluate(guess);
      const double tol = params_.newton.residual_tolerance_model;
      if (dot(residual, residual) <= tol * tol) {  // squared: no root per pixel
        uvw = seed_uvw = guess;
        cur_jac_[c] = cur_jac_[c - 1];  // still a good predictor for the next row
        // The extrapolation weighs the last solutions by 3, -3, 1, so their errors (up to
        // the tolerance) would grow along the row. The seed kept for the next pixels takes
        // a Newton step with the neighbour's Jacobian: no evaluation, and it shrinks that
        // error by the Jacobian's change over a pixel. The pixel's own answer stays the
        // checked `guess`.
        Vec3 step;
        if (solve3(cur_jac_[c], residual, step, 0.0)) seed_uvw = guess + step;
        return true;
      }
    }
    retry_prediction_at_ = col + kPredictionBackoff;
  }
  // Seeds in the order the strategy allows (Table 1 of the paper): the neighbour's solution,
  // Jacobian and pixel centre.
  struct Seed {
    const Vec3* uvw;
    const Mat3* jac;
    Vec3 x;
  };
  Seed seeds[6];
  int n = 0;
  const double dx = pitch_x_, dy = pitch_y_;
  const bool eight_neighbours = s == TracingStrategy::kFull || predicts;
  if (s != TracingStrategy::kNone && col > 0 && cur_ok_[c - 1]) seeds[n++] = {&cur_uvw_[c - 1], &cur_jac_[c - 1], x - Vec3{dx, 0, 0}};
  if ((s == TracingStrategy::kPreviousLine || eight_neighbours) && prev_ok_[c])
    seeds[n++] = {&prev_uvw_[c], &prev_jac_[c], x + Vec3{0, dy, 0}};
  if (eight_neighbours) {
    if (col > 0 && prev_ok_[c - 1]) seeds[n++] = {&prev_uvw_[c - 1], &prev_jac_[c - 1], x + Vec3{-dx, dy, 0}};
    if (col + 1 < width && prev_ok_[c + 1]) seeds[n++] = {&prev_uvw_[c + 1], &prev_jac_[c + 1], x + Vec3{dx, dy, 0}};
  }
  if (s == TracingStrategy::kFlood && n == 0) {
    // No neighbour is solved: the nearest solved pixel of the row above (either side), and
    // of this row to the left, as far as kFloodReach pixels away.
    constexpr int kFloodReach = 64;
    for (int k = 2; k <= kFloodReach; ++k) {
      if (col - k >= 0 && prev_ok_[c - static_cast<std::size_t>(k)]) {
        seeds[n++] = {&prev_uvw_[c - static_cast<std::size_t>(k)], &prev_jac_[c - static_cast<std::size_t>(k)], x + Vec3{-k * dx, dy, 0}};
        break;
      }
      if (col + k < width && prev_ok_[c + static_cast<std::size_t>(k)]) {
        seeds[n++] = {&prev_uvw_[c + static_cast<std::size_t>(k)], &prev_jac_[c + static_cast<std::size_t>(k)], x + Vec3{k * dx, dy, 0}};
        break;
      }
    }
    for (int k = 2; k <= kFloodReach && col - k >= 0; ++k)
      if (cur_ok_[c - static_cast<std::size_t>(k)]) {
        seeds[n++] = {&cur_uvw_[c - static_cast<std::size_t>(k)], &cur_jac_[c - static_cast<std::size_t>(k)], x - Vec3{k * dx, 0, 0}};
        break;
      }
  }
  std::optional<Vec3> outward;
  for (int i = 0; i < n; ++i) {
    const InverseResult r =
        invert_traced(volume_, x, *seeds[i].uvw, seeds[i].x, *seeds[i].jac, params_.newton, cur_jac_[c]);
    counters_.newton_evals += r.iterations;
    if (r.status == InverseStatus::kConverged) {
      uvw = seed_uvw = r.uvw;
      return true;
    }
    if (r.status == InverseStatus::kOutside) {
      // Newton from a neighbour walked off a face: the other neighbours would follow it
      // there. The face's normal lets the global solver prove "outside" quickly.
      outward = outward_hint(volume_, x, r.uvw);
      break;
    }
  }
  ++counters_.global_calls;
  const GlobalResult g = solver_.solve(x, params_.global, outward);
  switch (g.status) {
    case GlobalStatus::kNone: return false;
    case GlobalStatus::kIncomplete:
      ++counters_.unresolved;
      if (g.preimages.empty()) return false;
      break;
    case GlobalStatus::kMultiple: ++counters_.folded; break;
    case GlobalStatus::kUnique:
    case GlobalStatus::kDegenerate: break;
  }
  // Deterministic choice: the preimages are sorted by (u, v, w).
  uvw = seed_uvw = g.preimages.front().uvw;
  Vec3 unused;
  volume_.evaluate_jacobian(uvw, unused, cur_jac_[c]);
  return true;
}

void CellTracer::trace_row(const SliceLayout& L, int row, const std::vector<std::pair<int, int>>& spans, TracedRow& out) {
  out.cols.clear();
  out.uvw.clear();
  out.xyz.clear();
  if (row == last_row_ + 1) {
    std::swap(cur_uvw_, prev_uvw_);
    std::swap(cur_ok_, prev_ok_);
    std::swap(cur_jac_, prev_jac_);
  } else {
    std::fill(prev_ok_.begin(), prev_ok_.end(), 0);
  }
  std::fill(cur_ok_.begin(), cur_ok_.end(), 0);
  last_row_ = row;
  retry_prediction_at_ = 0;
  const double y = L.y_of_row(row);
  pitch_x_ = L.pitch_x_mm;
  pitch_y_ = L.pitch_y_mm;
  for (const auto& [c0, c1] : spans)
    for (int col = c0; col <= c1; ++col) {
      ++counters_.candidates;
      const Vec3 x{L.x_of_col(col), y, z_mm_};
      Vec3 uvw, seed;
      if (!solve_pixel(x, col, uvw, seed)) continue;
      cur_ok_[static_cast<std::size_t>(col)] = 1;
      cur_uvw_[static_cast<std::size_t>(col)] = seed;
      ++counters_.inside;
      out.cols.push_back(col);
      out.uvw.push_back(uvw);
      out.xyz.push_back(x);
    }
}

}  // namespace trivox::detail
