// Inverts every candidate pixel of one cell in one layer (lines 7-20 of Algorithm 1):
// Newton seeded by already solved neighbours, as the tracing strategy allows, with the
// global solver as the fallback that also decides pixels near the outline exactly.
#pragma once

#include <cstdint>
#include <vector>

#include "scanline.h"
#include "trivox/inverse/invert.h"
#include "trivox/slice/slice_params.h"

namespace trivox::detail {

struct TraceCounters {
  std::int64_t candidates = 0;     // pixels examined
  std::int64_t inside = 0;         // pixels whose inverse lies in the domain
  std::int64_t global_calls = 0;   // global solves
  std::int64_t newton_evals = 0;   // evaluations of V and J by Newton
  std::int64_t folded = 0;         // pixels with several regular preimages (fold)
  std::int64_t unresolved = 0;     // global solver ran out of budget

  TraceCounters& operator+=(const TraceCounters& o) noexcept;
};

// One row's inside pixels: columns and their parameters, in increasing column order.
struct TracedRow {
  std::vector<int> cols;
  std::vector<Vec3> uvw;
  std::vector<Vec3> xyz;
};

class CellTracer {
 public:
  CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px);

  // Starts a new layer at height z.
  void begin_layer(double z_mm);
  // Solves the candidate spans of `row` (rows must come in increasing order, each once per
  // layer; skipped rows simply leave no solved neighbours above).
  void trace_row(const SliceLayout& layout, int row, const std::vector<std::pair<int, int>>& spans, TracedRow& out);

  const TraceCounters& counters() const noexcept { return counters_; }

 private:
  // Solves one pixel: `uvw` is its answer (within the residual tolerance), `seed_uvw` what
  // later pixels start from (the answer, or a refinement of it that was not re-evaluated).
  bool solve_pixel(Vec3 x, int col, Vec3& uvw, Vec3& seed_uvw);

  const Volume& volume_;
  const GlobalSolver& solver_;
  const SliceParams& params_;
  double z_mm_ = 0;
  int last_row_ = -2;
  // Seeds from the current and previous rows (solved flag per column).
  std::vector<Vec3> cur_uvw_, prev_uvw_;
  std::vector<Mat3> cur_jac_, prev_jac_;  // Jacobians near the solutions, for prediction
  double pitch_x_ = 0, pitch_y_ = 0;  // mm, from the layout
  std::vector<std::uint8_t> cur_ok_, prev_ok_;
  TraceCounters counters_;
  // Row extrapolation resumes at this column after a failed guess.
  static constexpr int kPredictionBackoff = 8;
  int retry_prediction_at_ = 0;
};

}  // namespace trivox::detail
