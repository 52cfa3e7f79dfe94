// Inverts every candidate pixel of one cell in one layer (lines 7-20 of Algorithm 1):
// Newton seeded by already solved neighbours, as the tracing strategy allows, with the
// global solver as the fallback that also decides pixels near the outline exactly.
//
// Along a row each pixel starts from its left neighbours, so one row is a chain of dependent
// evaluations that leaves most of a core idle. The tracer therefore walks several rows at
// once, each a fixed number of columns behind the row above (every pixel reads the row above
// only up to kFloodReach columns ahead), and evaluates the pixels they have ready together
// (Volume::evaluate_many, evaluate_jacobian_many). Each pixel sees exactly the solved
// neighbours it would see if the rows were traced one after the other, so the answers do not
// depend on how many rows are in flight: one row at a time is the sequential reference the
// tests compare against.
//
// The predicting strategies (predict, flood) settle a pixel in one of three ways:
//   - a guess by the row's extrapolation, checked by one value-only evaluation (most pixels);
//   - a Jacobian step: a guess evaluated with its Jacobian, accepted when it or the Newton
//     step from it is certified by Taylor's remainder (after a guess missed, for the next
//     kJacobianRun pixels, and where the extrapolation has too few solved pixels);
//   - the slow path: Newton from the solved neighbours in turn, then the global solver (no
//     neighbour solved, or the Jacobian step not certified).
// The other strategies (the paper's Table 1) take the slow path for every pixel.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "scanline.h"
#include "trivox/inverse/invert.h"
#include "trivox/slice/slice_params.h"
#include "trivox/slice/slice_stats.h"

namespace trivox::detail {

// One row's inside pixels: columns and their parameters, in increasing column order.
struct TracedRow {
  std::vector<int> cols;
  std::vector<Vec3> uvw;
  std::vector<Vec3> xyz;
};

// The preimage whose material a pixel takes when the global solver finds several (a fold, a
// seam, a collapsed face): the one of largest |det J|, the lexicographically smallest
// (u, v, w) among equal ones. `preimages` is not empty and sorted by (u, v, w).
const Preimage& choose_preimage(const std::vector<Preimage>& preimages);

class CellTracer {
 public:
  // Rows traced at once by default: enough independent evaluations to fill the core.
  static constexpr int kDefaultRowsInFlight = 4;
  // Bytes a row of the ring holds per column of the bitmap (Row's per-column vectors and its
  // reserved output), and a traced pixel's bytes in a TracedRow.
  static constexpr std::size_t kRowBytesPerColumn =
      sizeof(Vec3) + 1 + sizeof(std::int32_t) + 2 * sizeof(Mat3) + sizeof(int) + 2 * sizeof(Vec3);
  static constexpr std::size_t kTracedBytesPerPixel = sizeof(int) + 2 * sizeof(Vec3);
  // What a tracer built with `rows_in_flight` holds for a bitmap `width_px` wide.
  static constexpr std::uint64_t ring_bytes(int width_px, int rows_in_flight = kDefaultRowsInFlight) {
    return static_cast<std::uint64_t>(rows_in_flight + 1) * static_cast<std::uint64_t>(width_px) * kRowBytesPerColumn;
  }

  // `folded`: the volume folds and the scene accepts it (docs/SCENE.md, "Folded cells"): every
  // candidate is decided by the global solver, which finds all its preimages, and takes the
  // one choose_preimage picks; no neighbour's solution stands in for it, since a neighbour
  // may lie on another sheet of the fold.
  CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px,
             int rows_in_flight = kDefaultRowsInFlight, bool folded = false);

  // Solves the candidate pixels of one layer at height z: every row of `spans` with
  // candidates, rows in increasing order. `on_row(row, traced)` receives each such row once
  // it and every row above it are done, in increasing row order; `traced` is valid during
  // the call only.
  void trace_layer(const SliceLayout& layout, double z_mm, const RowSpans& spans,
                   const std::function<void(int, const TracedRow&)>& on_row);

  // How the pixels traced so far were settled (trivox/slice/slice_stats.h).
  const TraceCounters& counters() const noexcept { return counters_; }
  // Pixels traced so far whose inverse lies in the volume's domain.
  std::int64_t inside() const noexcept { return inside_; }

  // Pixels of the row above that a pixel may read as seeds, ahead of its own column.
  static constexpr int kFloodReach = 64;
  // After a guess misses, the row's next this many pixels (the missed one included) take the
  // Jacobian step instead of a guess.
  static constexpr int kJacobianRun = 4;

 private:
  // One row being traced: its candidates, the solutions so far (seeds for the pixels to the
  // right and for the row below) and the Jacobians they were predicted with.
  struct Row {
    int row = -1;
    double y_mm = 0;
    const std::vector<std::pair<int, int>>* spans = nullptr;
    std::size_t span = 0;
    int col = 0;  // the next candidate
    bool done = true;
    std::vector<Vec3> uvw;             // per column: the seed kept for later pixels
    std::vector<std::uint8_t> ok;      // per column: solved
    std::vector<std::int32_t> jac_of;  // per solved column: the column of `jac` holding its Jacobian
    std::vector<Mat3> jac;             // at the columns where a Jacobian was evaluated
    std::vector<Mat3> jac_inverse;     // and its inverse (zero where J is singular)
    int jacobian_until = 0;            // columns before it take the Jacobian step
    bool check_pending = false;        // the next pixel's Jacobian step needs its end evaluated
    Vec3 check_at;                     // that end
    TracedRow out;
  };

  // A solved pixel as a seed for Newton: its solution, the Jacobian it was predicted with and
  // its centre.
  struct Seed {
    const Vec3* uvw;
    const Mat3* jac;
    Vec3 x;
  };
  // The flood's two farther seeds beyond the four neighbours.
  static constexpr int kMaxSeeds = 6;
  static Seed seed_at(const Row& r, int col, Vec3 pixel_x);
  // Whether `row` (the row above, or none) has column `col` solved.
  static bool solved(const Row* row, int col) { return row != nullptr && row->ok[static_cast<std::size_t>(col)] != 0; }
  // The solved neighbours of pixel x (the row's next) in the order the strategy tries them
  // (the paper's Table 1): left, above, above-left, above-right. Returns how many.
  int neighbour_seeds(const Row& r, const Row* above, Vec3 x, Seed* seeds) const;

  // How a row's next pixel is settled, and the parameter it is evaluated at: a guess, the end
  // of a Jacobian step that could not be certified (checked by its value), a Jacobian step,
  // or the slow path.
  enum class Step { kGuess, kCheck, kJacobian, kSlow };
  Step plan(const Row& r, const Row* above, Vec3 x, Vec3& at) const;
  // A guess's value within the tolerance of x: recorded. Else the row turns to Jacobian steps.
  bool accept_guess(Row& r, Vec3 x, Vec3 guess, Vec3 value);
  // A Jacobian step's outcome: recorded when certified; when its step could not be certified
  // (no second-derivative bounds, as for a rational volume) the step's end is checked next,
  // in a batch (returns false: the pixel is not settled yet); else the slow path.
  bool finish_jacobian_step(Row& r, const Row* above, Vec3 x, Vec3 at, Vec3 value, const Mat3& jacobian);
  // The checked end of a Jacobian step: recorded when within the tolerance, else the slow path.
  void finish_check(Row& r, const Row* above, Vec3 x, Vec3 at, Vec3 value);
  // Throws CancelledError once params_.stop is raised.
  void throw_if_stopped() const;
  // Newton from the solved neighbours in `r` and the row above (`above`, or none), then the
  // global solver; records the pixel if it lies in the cell.
  void solve_from_neighbours(Row& r, const Row* above, Vec3 x);
  void start_row(Row& r, int row, double y_mm, const std::vector<std::pair<int, int>>& spans);
  void record(Row& r, Vec3 x, Vec3 uvw, Vec3 seed, int jacobian_column);
  // r.jac[c] was just evaluated: keeps its inverse for the seeds of the guesses after it.
  void keep_jacobian(Row& r, std::size_t c);
  void advance(Row& r);
  Vec3 centre(const Row& r) const noexcept;

  const Volume& volume_;
  const GlobalSolver& solver_;
  const SliceParams& params_;
  GlobalSolveParams global_;  // params_.global, with params_.stop
  bool predicts_;             // the strategy guesses and takes Jacobian steps
  bool folded_;               // every pixel by the global solver
  int width_;
  int rows_in_flight_;
  double z_mm_ = 0;
  const SliceLayout* layout_ = nullptr;  // during trace_layer
  std::vector<Row> ring_;                // rows_in_flight + 1 slots: the rows in flight and the one above them
  TraceCounters counters_;
  std::int64_t inside_ = 0;
};

}  // namespace trivox::detail
