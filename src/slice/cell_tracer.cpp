#include "cell_tracer.h"

#include <algorithm>
#include <bit>
#include <climits>
#include <cstring>
#include <optional>

#include "inverse/newton.h"

namespace trivox::detail {

TraceCounters& TraceCounters::operator+=(const TraceCounters& o) noexcept {
  candidates += o.candidates;
  inside += o.inside;
  global_calls += o.global_calls;
  global_unseeded += o.global_unseeded;
  newton_evals += o.newton_evals;
  folded += o.folded;
  unresolved += o.unresolved;
  return *this;
}

namespace {

// The solved flags of columns c - 3 to c (c >= 3), one byte each, c - 3 in the low byte:
// one load instead of four for the predictor's test.
inline std::uint32_t solved_flags_at(const std::uint8_t* ok, std::size_t c) noexcept {
  std::uint32_t word;
  std::memcpy(&word, ok + c - 3, sizeof word);
  if constexpr (std::endian::native == std::endian::big) word = __builtin_bswap32(word);
  return word;
}

// Row by row: a plain assignment of the 72-byte matrix can compile, in the tracer, to a
// string move whose start-up cost is several times that of the nine loads and stores.
inline void copy_jacobian(const Mat3& from, Mat3& to) noexcept {
  for (std::size_t r = 0; r < 3; ++r) {
    const double a = from.m[r][0], b = from.m[r][1], c = from.m[r][2];
    to.m[r][0] = a;
    to.m[r][1] = b;
    to.m[r][2] = c;
  }
}

}  // namespace

CellTracer::CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px,
                       int rows_in_flight)
    : volume_(volume),
      solver_(solver),
      params_(params),
      width_(width_px),
      rows_in_flight_(std::max(1, rows_in_flight)),
      ring_(static_cast<std::size_t>(rows_in_flight_) + 1) {
  for (Row& r : ring_) {
    r.uvw.resize(static_cast<std::size_t>(width_px));
    r.jac.resize(static_cast<std::size_t>(width_px));
    r.ok.assign(static_cast<std::size_t>(width_px), 0);
  }
}

void CellTracer::start_row(Row& r, int row, double y_mm, const std::vector<std::pair<int, int>>& spans) {
  r.row = row;
  r.y_mm = y_mm;
  r.spans = &spans;
  r.span = 0;
  r.done = false;
  // Empty spans (first > last) hold no candidate.
  while (r.span < spans.size() && spans[r.span].first > spans[r.span].second) ++r.span;
  if (r.span == spans.size()) r.done = true;
  else r.col = spans[r.span].first;
  std::fill(r.ok.begin(), r.ok.end(), 0);
  r.retry_prediction_at = 0;
  r.correct_until = -1;
  r.guess_corrected = false;
  r.out.cols.clear();
  r.out.uvw.clear();
  r.out.xyz.clear();
}

Vec3 CellTracer::centre(const Row& r) const noexcept { return {layout_->x_of_col(r.col), r.y_mm, z_mm_}; }

void CellTracer::advance(Row& r) {
  const auto& spans = *r.spans;
  if (r.col < spans[r.span].second) {
    ++r.col;
    return;
  }
  do ++r.span;
  while (r.span < spans.size() && spans[r.span].first > spans[r.span].second);
  if (r.span == spans.size()) r.done = true;
  else r.col = spans[r.span].first;
}

void CellTracer::record(Row& r, Vec3 x, Vec3 uvw, Vec3 seed) {
  const auto c = static_cast<std::size_t>(r.col);
  r.ok[c] = 1;
  r.uvw[c] = seed;
  ++counters_.inside;
  r.out.cols.push_back(r.col);
  r.out.uvw.push_back(uvw);
  r.out.xyz.push_back(x);
}

// Along a row the inverse map is smooth: the quadratic through the last three solutions
// predicts the next one to O(pitch^3), usually within the residual tolerance, so a single
// value-only evaluation settles the pixel. Where the map bends too fast for it (small or
// strongly curved cells), a failed guess costs an evaluation, so after a corrected guess
// (below) fails the next few pixels go straight to Newton.
//
// Where the row above is solved at the same four columns, its own extrapolation's miss is
// known there, and this row's miss is nearly the same (the two differ by one row pitch's
// change of the third difference): adding it corrects the guess to O(pitch^3 x row pitch).
// On the paper-size duck that halves the guesses that miss; but where the plain guess
// rarely misses the correction only costs time (and misses slightly more often on knot
// lines that cross the rows at a slant), so it is used for a stretch of the row after a
// plain guess missed (docs/PERFORMANCE.md).
bool CellTracer::prediction(Row& r, const Row* above, Vec3& guess) {
  const TracingStrategy s = params_.tracing;
  if (s != TracingStrategy::kPredict && s != TracingStrategy::kFlood) return false;
  const int col = r.col;
  const auto c = static_cast<std::size_t>(col);
  if (col < 3 || col < r.retry_prediction_at || (solved_flags_at(r.ok.data(), c) & 0x00ffffffu) != 0x00010101u) return false;
  guess = 3.0 * (r.uvw[c - 1] - r.uvw[c - 2]) + r.uvw[c - 3];
  r.guess_corrected = col <= r.correct_until && above != nullptr && solved_flags_at(above->ok.data(), c) == 0x01010101u;
  if (r.guess_corrected) {
    const std::vector<Vec3>& a = above->uvw;
    guess = guess + ((a[c] - a[c - 3]) - 3.0 * (a[c - 1] - a[c - 2]));
  }
  if (!volume_.domain().contains(guess)) {
    r.retry_prediction_at = col + kPredictionBackoff;
    return false;
  }
  return true;
}

bool CellTracer::accept_prediction(Row& r, Vec3 x, Vec3 guess, Vec3 value) {
  ++counters_.newton_evals;
  const Vec3 residual = x - value;
  const double tol = params_.newton.residual_tolerance_model;
  if (!(dot(residual, residual) <= tol * tol)) {  // squared: no root per pixel
    // A plain guess that misses hands the next pixels to the corrected guess; a corrected
    // one that misses, to Newton for a few pixels.
    if (r.guess_corrected) r.retry_prediction_at = r.col + kPredictionBackoff;
    else r.correct_until = r.col + kCorrectedRun;
    return false;
  }
  const auto c = static_cast<std::size_t>(r.col);
  // The neighbour's Jacobian is still a good predictor for the next row.
  const Mat3& jacobian = r.jac[c - 1];
  copy_jacobian(jacobian, r.jac[c]);
  // The extrapolation weighs the last solutions by 3, -3, 1, so their errors (up to the
  // tolerance) would grow along the row. The seed kept for the next pixels takes a Newton
  // step with the neighbour's Jacobian: no evaluation, and it shrinks that error by the
  // Jacobian's change over a pixel. The pixel's own answer stays the checked `guess`.
  Vec3 seed = guess, step;
  if (solve3(jacobian, residual, step, 0.0)) seed = guess + step;
  record(r, x, guess, seed);
  return true;
}

void CellTracer::solve_from_neighbours(Row& r, const Row* above, Vec3 x) {
  const int col = r.col;
  const auto c = static_cast<std::size_t>(col);
  const TracingStrategy s = params_.tracing;
  const bool predicts = s == TracingStrategy::kPredict || s == TracingStrategy::kFlood;
  // Seeds in the order the strategy allows (Table 1 of the paper): the neighbour's solution,
  // Jacobian and pixel centre.
  struct Seed {
    const Vec3* uvw;
    const Mat3* jac;
    Vec3 x;
  };
  Seed seeds[6];
  int n = 0;
  const double dx = layout_->pitch_x_mm, dy = layout_->pitch_y_mm;
  const bool eight_neighbours = s == TracingStrategy::kFull || predicts;
  auto above_ok = [&](int k) { return above != nullptr && above->ok[static_cast<std::size_t>(k)] != 0; };
  auto above_seed = [&](int k, Vec3 at) {
    return Seed{&above->uvw[static_cast<std::size_t>(k)], &above->jac[static_cast<std::size_t>(k)], at};
  };
  if (s != TracingStrategy::kNone && col > 0 && r.ok[c - 1]) seeds[n++] = {&r.uvw[c - 1], &r.jac[c - 1], x - Vec3{dx, 0, 0}};
  if ((s == TracingStrategy::kPreviousLine || eight_neighbours) && above_ok(col)) seeds[n++] = above_seed(col, x + Vec3{0, dy, 0});
  if (eight_neighbours) {
    if (col > 0 && above_ok(col - 1)) seeds[n++] = above_seed(col - 1, x + Vec3{-dx, dy, 0});
    if (col + 1 < width_ && above_ok(col + 1)) seeds[n++] = above_seed(col + 1, x + Vec3{dx, dy, 0});
  }
  if (s == TracingStrategy::kFlood && n == 0) {
    // No neighbour is solved: the nearest solved pixel of the row above (either side), and
    // of this row to the left, as far as kFloodReach pixels away.
    for (int k = 2; k <= kFloodReach; ++k) {
      if (col - k >= 0 && above_ok(col - k)) {
        seeds[n++] = above_seed(col - k, x + Vec3{-k * dx, dy, 0});
        break;
      }
      if (col + k < width_ && above_ok(col + k)) {
        seeds[n++] = above_seed(col + k, x + Vec3{k * dx, dy, 0});
        break;
      }
    }
    for (int k = 2; k <= kFloodReach && col - k >= 0; ++k)
      if (r.ok[c - static_cast<std::size_t>(k)]) {
        const auto from = c - static_cast<std::size_t>(k);
        seeds[n++] = {&r.uvw[from], &r.jac[from], x - Vec3{k * dx, 0, 0}};
        break;
      }
  }
  std::optional<Vec3> outward;
  for (int i = 0; i < n; ++i) {
    const InverseResult res =
        invert_traced(volume_, x, *seeds[i].uvw, seeds[i].x, *seeds[i].jac, params_.newton, r.jac[c]);
    counters_.newton_evals += res.iterations;
    if (res.status == InverseStatus::kConverged) {
      record(r, x, res.uvw, res.uvw);
      return;
    }
    if (res.status == InverseStatus::kOutside) {
      // Newton from a neighbour walked off a face: the other neighbours would follow it
      // there. The face's normal lets the global solver prove "outside" quickly.
      outward = outward_hint(volume_, x, res.uvw);
      break;
    }
  }
  ++counters_.global_calls;
  if (n == 0) ++counters_.global_unseeded;
  const GlobalResult g = solver_.solve(x, params_.global, outward);
  switch (g.status) {
    case GlobalStatus::kNone: return;
    case GlobalStatus::kIncomplete:
      ++counters_.unresolved;
      if (g.preimages.empty()) return;
      break;
    case GlobalStatus::kMultiple: ++counters_.folded; break;
    case GlobalStatus::kUnique:
    case GlobalStatus::kDegenerate: break;
  }
  // Deterministic choice: the preimages are sorted by (u, v, w).
  const Vec3 uvw = g.preimages.front().uvw;
  Vec3 unused;
  volume_.evaluate_jacobian(uvw, unused, r.jac[c]);
  record(r, x, uvw, uvw);
}

void CellTracer::trace_layer(const SliceLayout& layout, double z_mm, const RowSpans& spans,
                             const std::function<void(int, const TracedRow&)>& on_row) {
  layout_ = &layout;
  z_mm_ = z_mm;
  const auto slots = ring_.size();
  // Rows with candidates, numbered in order: number q lives in slot q % slots, so the slots
  // hold the rows in flight and the last finished one, which the first of them reads.
  std::vector<int> rows;
  for (int row = 0; row < static_cast<int>(spans.size()); ++row)
    if (!spans[static_cast<std::size_t>(row)].empty()) rows.push_back(row);
  const auto total = rows.size();
  auto slot = [&](std::size_t q) -> Row& { return ring_[q % slots]; };
  // The row above number q: its slot when it is the image row just above, else none.
  auto above_of = [&](std::size_t q) -> const Row* {
    return q > 0 && rows[q - 1] == rows[q] - 1 ? &slot(q - 1) : nullptr;
  };

  struct Pending {
    Row* row;
    const Row* above;
    Vec3 x;
  };
  std::vector<Pending> pending;
  std::vector<Vec3> guesses, values;
  pending.reserve(ring_.size());
  std::size_t oldest = 0, next = 0;
  while (oldest < total) {
    while (next < total && next < oldest + static_cast<std::size_t>(rows_in_flight_)) {
      const int row = rows[next];
      start_row(slot(next), row, layout.y_of_row(row), spans[static_cast<std::size_t>(row)]);
      ++next;
    }
    // Each row in flight solves pixels until one needs its row prediction evaluated (then
    // waits for the batch) or until it would read a pixel of the row above not solved yet.
    pending.clear();
    guesses.clear();
    for (std::size_t q = oldest; q < next; ++q) {
      Row& r = slot(q);
      const Row* above = above_of(q);
      const int limit = above == nullptr || above->done ? INT_MAX : above->col - kFloodReach - 1;
      while (!r.done && r.col <= limit) {
        ++counters_.candidates;
        const Vec3 x = centre(r);
        Vec3 guess;
        if (prediction(r, above, guess)) {
          pending.push_back({&r, above, x});
          guesses.push_back(guess);
          break;
        }
        solve_from_neighbours(r, above, x);
        advance(r);
      }
    }
    values.resize(guesses.size());
    volume_.evaluate_many(guesses, values);
    for (std::size_t i = 0; i < pending.size(); ++i) {
      Row& r = *pending[i].row;
      if (!accept_prediction(r, pending[i].x, guesses[i], values[i])) solve_from_neighbours(r, pending[i].above, pending[i].x);
      advance(r);
    }
    while (oldest < next && slot(oldest).done) {
      const Row& r = slot(oldest);
      on_row(r.row, r.out);
      ++oldest;
    }
  }
  layout_ = nullptr;
}

}  // namespace trivox::detail
