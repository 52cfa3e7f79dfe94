#include "cell_tracer.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <optional>

#include "check.h"
#include "function_clones.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/inverse/detail/trace.h"

namespace trivox::detail {

namespace {

// Whether columns c - 4 to c - 1 (c >= 4) are all solved: one load instead of four.
inline bool four_solved_before(const std::uint8_t* ok, std::size_t c) noexcept {
  std::uint32_t word;
  std::memcpy(&word, ok + c - 4, sizeof word);
  return word == 0x01010101u;  // every flag 1, in either byte order
}

}  // namespace

const Preimage& choose_preimage(const std::vector<Preimage>& preimages) {
  const Preimage* best = &preimages.front();
  for (const Preimage& p : preimages)
    if (std::abs(p.det) > std::abs(best->det)) best = &p;  // strictly: the first of equal ones stays
  return *best;
}

CellTracer::CellTracer(const Volume& volume, const GlobalSolver& solver, const SliceParams& params, int width_px,
                       int rows_in_flight, bool folded)
    : volume_(volume),
      solver_(solver),
      params_(params),
      global_(params.global),
      predicts_(!folded && (params.tracing == TracingStrategy::kPredict || params.tracing == TracingStrategy::kFlood)),
      folded_(folded),
      width_(width_px),
      rows_in_flight_(std::max(1, rows_in_flight)),
      ring_(static_cast<std::size_t>(rows_in_flight_) + 1) {
  const auto w = static_cast<std::size_t>(width_px);
  for (Row& r : ring_) {
    r.uvw.resize(w);
    r.ok.assign(w, 0);
    r.jac_of.resize(w);
    r.jac.resize(w);
    r.jac_inverse.resize(w);
    r.out.cols.reserve(w);
    r.out.uvw.reserve(w);
    r.out.xyz.reserve(w);
  }
  global_.stop = params.stop;
}

void CellTracer::start_row(Row& r, int row, double y_mm, const std::vector<std::pair<int, int>>& spans) {
  for (const auto& [first, last] : spans)
    if (first <= last) {
      TRIVOX_CHECK_GE(first, 0);
      TRIVOX_CHECK_LT(last, width_);
    }
  r.row = row;
  r.y_mm = y_mm;
  r.spans = &spans;
  r.span = 0;
  r.done = false;
  // Empty spans (first > last) hold no candidate.
  while (r.span < spans.size() && spans[r.span].first > spans[r.span].second) ++r.span;
  if (r.span == spans.size())
    r.done = true;
  else
    r.col = spans[r.span].first;
  std::fill(r.ok.begin(), r.ok.end(), 0);
  r.jacobian_until = 0;
  r.check_pending = false;
  r.out.cols.clear();
  r.out.uvw.clear();
  r.out.xyz.clear();
}

Vec3 CellTracer::centre(const Row& r) const noexcept { return {layout_->x_of_col(r.col), r.y_mm, z_mm_}; }

inline void CellTracer::advance(Row& r) {
  ++counters_.candidates;
  const auto& spans = *r.spans;
  if (r.col < spans[r.span].second) {
    ++r.col;
    return;
  }
  do ++r.span;
  while (r.span < spans.size() && spans[r.span].first > spans[r.span].second);
  if (r.span == spans.size())
    r.done = true;
  else
    r.col = spans[r.span].first;
}

TRIVOX_CLONED void CellTracer::record(Row& r, Vec3 x, Vec3 uvw, Vec3 seed, int jacobian_column) {
  const auto c = static_cast<std::size_t>(r.col);
  TRIVOX_CHECK_LT(c, r.ok.size());
  // A row's solved columns increase (TracedRow's contract).
  if (!r.out.cols.empty()) TRIVOX_CHECK_LT(r.out.cols.back(), r.col);
  r.ok[c] = 1;
  r.uvw[c] = seed;
  r.jac_of[c] = jacobian_column;
  ++inside_;
  r.out.cols.push_back(r.col);
  r.out.uvw.push_back(uvw);
  r.out.xyz.push_back(x);
}

void CellTracer::keep_jacobian(Row& r, std::size_t c) {
  // A singular Jacobian gives the seeds no correction (the zero matrix).
  if (!invert3(r.jac[c], r.jac_inverse[c], 0.0)) r.jac_inverse[c] = Mat3{};
}

CellTracer::Seed CellTracer::seed_at(const Row& r, int col, Vec3 pixel_x) {
  const auto c = static_cast<std::size_t>(col);
  TRIVOX_CHECK(r.ok[c] != 0);  // only solved pixels seed
  TRIVOX_CHECK_GE(r.jac_of[c], 0);
  return {&r.uvw[c], &r.jac[static_cast<std::size_t>(r.jac_of[c])], pixel_x};
}

int CellTracer::neighbour_seeds(const Row& r, const Row* above, Vec3 x, Seed* seeds) const {
  const int col = r.col;
  const auto c = static_cast<std::size_t>(col);
  const TracingStrategy s = params_.tracing;
  const double dx = layout_->pitch_x_mm, dy = layout_->pitch_y_mm;
  const bool eight_neighbours = s == TracingStrategy::kFull || predicts_;
  int n = 0;
  if (s != TracingStrategy::kNone && col > 0 && r.ok[c - 1]) seeds[n++] = seed_at(r, col - 1, x - Vec3{dx, 0, 0});
  if ((s == TracingStrategy::kPreviousLine || eight_neighbours) && solved(above, col))
    seeds[n++] = seed_at(*above, col, x + Vec3{0, dy, 0});
  if (eight_neighbours) {
    if (col > 0 && solved(above, col - 1)) seeds[n++] = seed_at(*above, col - 1, x + Vec3{-dx, dy, 0});
    if (col + 1 < width_ && solved(above, col + 1)) seeds[n++] = seed_at(*above, col + 1, x + Vec3{dx, dy, 0});
  }
  return n;
}

// Along a row the inverse map is smooth: the cubic through the last four solutions predicts
// the next one to O(pitch^4), usually within the residual tolerance, so a single value-only
// evaluation settles the pixel. Where the map bends too fast for it (small or strongly
// curved cells, knot lines of a C1 volume), the guess misses by a little more than the
// tolerance; the Jacobian step from the same guess then settles the pixel with one
// evaluation of V and J, and the next few pixels take that step straight away. A pixel with
// fewer than four solved pixels to its left starts from the first-order prediction of its
// first solved neighbour (the slow path's first seed), a Jacobian step as well.
inline CellTracer::Step CellTracer::plan(const Row& r, const Row* above, Vec3 x, Vec3& at) const {
  if (!predicts_) return Step::kSlow;
  if (r.check_pending) {
    at = r.check_at;
    return Step::kCheck;
  }
  const int col = r.col;
  const auto c = static_cast<std::size_t>(col);
  if (col >= 4 && four_solved_before(r.ok.data(), c)) {
    const Vec3* u = r.uvw.data() + c;
    at = 4.0 * (u[-1] + u[-3]) - 6.0 * u[-2] - u[-4];
    if (volume_.domain().contains(at)) return col < r.jacobian_until ? Step::kJacobian : Step::kGuess;
  }
  Seed seeds[kMaxSeeds];
  if (neighbour_seeds(r, above, x, seeds) == 0) return Step::kSlow;
  at = predict_from_seed(volume_.domain(), x, *seeds[0].uvw, seeds[0].x, *seeds[0].jac);
  return Step::kJacobian;
}

inline bool CellTracer::accept_guess(Row& r, Vec3 x, Vec3 guess, Vec3 value) {
  ++counters_.newton_evals;
  ++counters_.guesses;
  const Vec3 residual = x - value;
  const double tol = params_.newton.residual_tolerance_model;
  if (!(dot(residual, residual) <= tol * tol)) {  // squared: no root per pixel
    ++counters_.guess_misses;
    r.jacobian_until = r.col + kJacobianRun;
    return false;
  }
  // The extrapolation weighs the last solutions by 4, -6, 4, -1, so their errors (up to the
  // tolerance) would grow along the row. The seed kept for the next pixels takes a Newton
  // step with the neighbour's Jacobian: no evaluation, and it shrinks that error by the
  // Jacobian's change since it was evaluated. The pixel's own answer stays the checked guess.
  const int jacobian_column = r.jac_of[static_cast<std::size_t>(r.col) - 1];
  record(r, x, guess, guess + r.jac_inverse[static_cast<std::size_t>(jacobian_column)] * residual, jacobian_column);
  return true;
}

bool CellTracer::finish_jacobian_step(Row& r, const Row* above, Vec3 x, Vec3 at, Vec3 value, const Mat3& jacobian) {
  ++counters_.newton_evals;
  ++counters_.jacobian_steps;
  const auto c = static_cast<std::size_t>(r.col);
  const NewtonStepCheck check = check_newton_step(volume_, x, at, value, jacobian, params_.newton);
  if (check.converged) {
    r.jac[c] = jacobian;
    keep_jacobian(r, c);
    // As for a guess, an answer that needed no step keeps the step as its seed.
    const Vec3 seed = check.uvw == at ? at + r.jac_inverse[c] * (x - value) : check.uvw;
    record(r, x, check.uvw, seed, r.col);
    return true;
  }
  if (check.stepped) {
    r.jac[c] = jacobian;
    r.check_pending = true;
    r.check_at = check.target;
    return false;
  }
  solve_from_neighbours(r, above, x);
  return true;
}

void CellTracer::finish_check(Row& r, const Row* above, Vec3 x, Vec3 at, Vec3 value) {
  ++counters_.newton_evals;
  r.check_pending = false;
  const Vec3 residual = x - value;
  const double tol = params_.newton.residual_tolerance_model;
  if (dot(residual, residual) <= tol * tol) {
    const auto c = static_cast<std::size_t>(r.col);
    keep_jacobian(r, c);
    record(r, x, at, at, r.col);
    return;
  }
  solve_from_neighbours(r, above, x);
}

// A raised stop flag ends the layer between batches and before each slow-path pixel, whose
// global solve is the tracer's largest unit of work (a row of a pathological job, such as a
// high-order rational cell traced without seeds, may take seconds); the job then counts the
// layer as not done.
void CellTracer::throw_if_stopped() const { trivox::throw_if_stopped(params_.stop, "tracing a layer"); }

void CellTracer::solve_from_neighbours(Row& r, const Row* above, Vec3 x) {
  throw_if_stopped();
  ++counters_.slow_path_pixels;
  const int col = r.col;
  const auto c = static_cast<std::size_t>(col);
  Seed seeds[kMaxSeeds];
  int n = folded_ ? 0 : neighbour_seeds(r, above, x, seeds);
  const double dx = layout_->pitch_x_mm, dy = layout_->pitch_y_mm;
  if (params_.tracing == TracingStrategy::kFlood && n == 0 && !folded_) {
    // No neighbour is solved: the nearest solved pixel of the row above (either side), and
    // of this row to the left, as far as kFloodReach pixels away.
    for (int k = 2; k <= kFloodReach; ++k) {
      if (col - k >= 0 && solved(above, col - k)) {
        seeds[n++] = seed_at(*above, col - k, x + Vec3{-k * dx, dy, 0});
        break;
      }
      if (col + k < width_ && solved(above, col + k)) {
        seeds[n++] = seed_at(*above, col + k, x + Vec3{k * dx, dy, 0});
        break;
      }
    }
    for (int k = 2; k <= kFloodReach && col - k >= 0; ++k)
      if (r.ok[c - static_cast<std::size_t>(k)]) {
        seeds[n++] = seed_at(r, col - k, x - Vec3{k * dx, 0, 0});
        break;
      }
  }
  std::optional<Vec3> outward;
  for (int i = 0; i < n; ++i) {
    const InverseResult res =
        invert_traced(volume_, x, *seeds[i].uvw, seeds[i].x, *seeds[i].jac, params_.newton, r.jac[c]);
    counters_.newton_evals += res.iterations;
    if (res.status == InverseStatus::kConverged) {
      keep_jacobian(r, c);
      record(r, x, res.uvw, res.uvw, col);
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
  const GlobalResult g = solver_.solve(x, global_, outward);
  switch (g.status) {
    case GlobalStatus::kNone: return;
    case GlobalStatus::kIncomplete:
      ++counters_.unresolved_pixels;
      if (g.preimages.empty()) return;
      break;
    case GlobalStatus::kMultiple: ++counters_.folded_pixels; break;
    case GlobalStatus::kUnique:
    case GlobalStatus::kDegenerate: break;
  }
  const Vec3 uvw = choose_preimage(g.preimages).uvw;
  Vec3 unused;
  volume_.evaluate_jacobian(uvw, unused, r.jac[c]);
  keep_jacobian(r, c);
  record(r, x, uvw, uvw, col);
}

TRIVOX_CLONED void CellTracer::trace_layer(const SliceLayout& layout, double z_mm, const RowSpans& spans,
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

  // The pixels the rows in flight have ready (at most one each), evaluated together:
  // guesses by value only, Jacobian steps with their Jacobians.
  struct Pending {
    Row* row;
    const Row* above;
    Vec3 x;
    bool check = false;  // in the value batch: a Jacobian step's end, not a guess
  };
  const auto most = static_cast<std::size_t>(rows_in_flight_);
  std::vector<Pending> guessing(most), stepping(most);
  std::vector<Vec3> guess_at(most), guess_value(most), step_at(most), step_value(most);
  std::vector<Mat3> step_jacobian(most);
  std::size_t oldest = 0, next = 0;
  while (oldest < total) {
    throw_if_stopped();
    while (next < total && next < oldest + most) {
      const int row = rows[next];
      start_row(slot(next), row, layout.y_of_row(row), spans[static_cast<std::size_t>(row)]);
      ++next;
    }
    // Each row in flight settles pixels on the slow path until one is ready for the batch
    // or until it would read a pixel of the row above not solved yet.
    std::size_t guesses = 0, steps = 0;
    for (std::size_t q = oldest; q < next; ++q) {
      Row& r = slot(q);
      const Row* above = above_of(q);
      const int limit = above == nullptr || above->done ? INT_MAX : above->col - kFloodReach - 1;
      while (!r.done && r.col <= limit) {
        const Vec3 x = centre(r);
        Vec3 at;
        const Step step = plan(r, above, x, at);
        if (step == Step::kGuess || step == Step::kCheck) {
          // Field by field: an aggregate copy can be stored in halves and loaded whole, which
          // stalls the load until the stores retire.
          Pending& p = guessing[guesses];
          p.row = &r;
          p.above = above;
          p.x = x;
          p.check = step == Step::kCheck;
          guess_at[guesses++] = at;
          break;
        }
        if (step == Step::kJacobian) {
          Pending& p = stepping[steps];
          p.row = &r;
          p.above = above;
          p.x = x;
          step_at[steps++] = at;
          break;
        }
        solve_from_neighbours(r, above, x);
        advance(r);
      }
    }
    volume_.evaluate_many(std::span(guess_at).first(guesses), std::span(guess_value).first(guesses));
    volume_.evaluate_jacobian_many(std::span(step_at).first(steps), std::span(step_value).first(steps),
                                   std::span(step_jacobian).first(steps));
    // A guess that misses stays the row's next pixel, its Jacobian step in the next batch;
    // so does a Jacobian step whose end is to be checked.
    for (std::size_t i = 0; i < guesses; ++i) {
      const Pending& p = guessing[i];
      if (p.check) {
        finish_check(*p.row, p.above, p.x, guess_at[i], guess_value[i]);
        advance(*p.row);
      } else if (accept_guess(*p.row, p.x, guess_at[i], guess_value[i])) {
        advance(*p.row);
      }
    }
    for (std::size_t i = 0; i < steps; ++i) {
      const Pending& p = stepping[i];
      if (finish_jacobian_step(*p.row, p.above, p.x, step_at[i], step_value[i], step_jacobian[i])) advance(*p.row);
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
