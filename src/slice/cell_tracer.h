// Inverts every candidate pixel of one cell in one layer (lines 7-20 of Algorithm 1):
// Newton seeded by already solved neighbours, as the tracing strategy allows, with the
// global solver as the fallback that also decides pixels near the outline exactly.
//
// Along a row each pixel starts from its left neighbours, so one row is a chain of dependent
// evaluations that leaves most of a core idle. The tracer therefore walks several rows at
// once, each a fixed number of columns behind the row above (every pixel reads the row above
// only up to kFloodReach columns ahead), and evaluates their row predictions together
// (Volume::evaluate_many). Each pixel sees exactly the solved neighbours it would see if the
// rows were traced one after the other, so the answers do not depend on how many rows are in
// flight: one row at a time is the sequential reference the tests compare against.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "scanline.h"
#include "trivox/inverse/invert.h"
#include "trivox/slice/slice_params.h"

namespace trivox::detail {

struct TraceCounters {
  std::int64_t candidates = 0;     // pixels examined
  std::int64_t inside = 0;         // pixels whose inverse lies in the domain
  std::int64_t global_calls = 0;   // global solves
  std::int64_t global_unseeded = 0;  // of which for a pixel with no solved neighbour to start from
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
  // Rows traced at once by default: enough independent evaluations to fill the core.
  static constexpr int kDefaultRowsInFlight = 4;

  CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px,
             int rows_in_flight = kDefaultRowsInFlight);

  // Solves the candidate pixels of one layer at height z: every row of `spans` with
  // candidates, rows in increasing order. `on_row(row, traced)` receives each such row once
  // it and every row above it are done, in increasing row order; `traced` is valid during
  // the call only.
  void trace_layer(const SliceLayout& layout, double z_mm, const RowSpans& spans,
                   const std::function<void(int, const TracedRow&)>& on_row);

  const TraceCounters& counters() const noexcept { return counters_; }

  // Pixels of the row above that a pixel may read as seeds, ahead of its own column.
  static constexpr int kFloodReach = 64;

 private:
  // One row being traced: its candidates, the solutions so far (seeds for the pixels to the
  // right and for the row below) and the predictor's state.
  struct Row {
    int row = -1;
    double y_mm = 0;
    const std::vector<std::pair<int, int>>* spans = nullptr;
    std::size_t span = 0;
    int col = 0;        // the next candidate
    bool done = true;
    std::vector<Vec3> uvw;   // per column: the seed kept for later pixels
    std::vector<Mat3> jac;   // per column: the Jacobian near it, for prediction
    std::vector<std::uint8_t> ok;  // per column: solved
    int retry_prediction_at = 0;
    int correct_until = -1;        // the last column whose guess adds the row above's miss
    bool guess_corrected = false;  // whether the pending guess did
    TracedRow out;
  };

  void start_row(Row& r, int row, double y_mm, const std::vector<std::pair<int, int>>& spans);
  // The row extrapolation's guess for the row's next pixel, when it should be tried (every
  // pixel it uses solved, not backed off, the guess inside the domain).
  bool prediction(Row& r, const Row* above, Vec3& guess);
  // Whether the guess's value is within the tolerance of x; records the pixel if so, else
  // backs the prediction off.
  bool accept_prediction(Row& r, Vec3 x, Vec3 guess, Vec3 value);
  // Newton from the solved neighbours in `r` and the row above (`above`, or none), then the
  // global solver; records the pixel if it lies in the cell.
  void solve_from_neighbours(Row& r, const Row* above, Vec3 x);
  void record(Row& r, Vec3 x, Vec3 uvw, Vec3 seed);
  void advance(Row& r);
  Vec3 centre(const Row& r) const noexcept;

  const Volume& volume_;
  const GlobalSolver& solver_;
  const SliceParams& params_;
  int width_;
  int rows_in_flight_;
  double z_mm_ = 0;
  const SliceLayout* layout_ = nullptr;  // during trace_layer
  std::vector<Row> ring_;  // rows_in_flight + 1 slots: the rows in flight and the one above them
  TraceCounters counters_;
  // Row extrapolation resumes this many columns after a failed guess.
  static constexpr int kPredictionBackoff = 8;
  // After a plain row guess misses, the next this many columns add the row above's miss.
  static constexpr int kCorrectedRun = 32;
};

}  // namespace trivox::detail
