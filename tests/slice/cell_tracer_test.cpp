// The tracer's fast paths (row extrapolation, batched Jacobian steps, neighbour-predicted
// Newton, hinted global solves) against the slow reference: the global solver on every pixel
// of whole rows.
#include "slice/cell_tracer.h"

#include <cmath>
#include <cstdint>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/slice/layout.h"

namespace trivox {
namespace {

// A 600 x 300 dpi grid over the volume's bounding rectangle.
SliceLayout layout_over(const Volume& v) {
  SliceLayout L;
  L.pitch_x_mm = 25.4 / 600;
  L.pitch_y_mm = 25.4 / 300;
  L.x0_mm = v.bounds().lo.x - 2 * L.pitch_x_mm;
  L.y_top_mm = v.bounds().hi.y + 2 * L.pitch_y_mm;
  L.width_px = static_cast<int>((v.bounds().hi.x - L.x0_mm) / L.pitch_x_mm) + 3;
  L.height_px = static_cast<int>((L.y_top_mm - v.bounds().lo.y) / L.pitch_y_mm) + 3;
  return L;
}

// A strongly twisted and bent quadratic volume: along its rows the cubic extrapolation of
// the last four solutions misses the tolerance now and then, so the Jacobian steps (and, on
// whole rows, the slow path for the pixels around the part) are all exercised.
Volume strongly_bent_volume() {
  const KnotVector k3 = KnotVector::clamped_uniform(3, 10);
  return test::twisted_bent_volume(k3, k3, k3, {6, 6, 3}, 2.0, 0.5);
}

// The inside pixels of a layer as spans, from a first trace of whole rows: tracing only them
// leaves out the evaluations that prove the pixels around the part outside.
detail::RowSpans inside_spans(const Volume& v, const GlobalSolver& solver, const SliceParams& params,
                              const SliceLayout& L, double z) {
  detail::RowSpans inside(static_cast<std::size_t>(L.height_px));
  detail::CellTracer finder(v, solver, params, L.width_px);
  const detail::RowSpans whole_rows(static_cast<std::size_t>(L.height_px), {{0, L.width_px - 1}});
  finder.trace_layer(L, z, whole_rows, [&](int row, const detail::TracedRow& traced) {
    auto& spans = inside[static_cast<std::size_t>(row)];
    for (int col : traced.cols)
      if (!spans.empty() && spans.back().second == col - 1)
        spans.back().second = col;
      else
        spans.push_back({col, col});
  });
  return inside;
}

void expect_agreement_with_global_solver(const Volume& v, std::initializer_list<TracingStrategy> strategies) {
  const GlobalSolver solver(v);
  const SliceLayout L = layout_over(v);
  const double z = 0.5 * (v.bounds().lo.z + v.bounds().hi.z);

  for (TracingStrategy strategy : strategies) {
    SliceParams params;
    params.tracing = strategy;
    detail::CellTracer tracer(v, solver, params, L.width_px);
    const detail::RowSpans whole_rows(static_cast<std::size_t>(L.height_px), {{0, L.width_px - 1}});
    std::vector<detail::TracedRow> rows(static_cast<std::size_t>(L.height_px));
    tracer.trace_layer(L, z, whole_rows,
                       [&](int row, const detail::TracedRow& traced) { rows[static_cast<std::size_t>(row)] = traced; });
    int inside = 0, mismatched = 0;
    for (int row = 0; row < L.height_px; ++row) {
      const detail::TracedRow& traced = rows[static_cast<std::size_t>(row)];
      std::size_t next = 0;
      for (int col = 0; col < L.width_px; ++col) {
        const Vec3 x{L.x_of_col(col), L.y_of_row(row), z};
        const GlobalResult g = solver.solve(x);
        const bool traced_inside = next < traced.cols.size() && traced.cols[next] == col;
        const bool global_inside = !g.preimages.empty();
        if (traced_inside != global_inside) {
          if (++mismatched < 5) ADD_FAILURE() << to_string(strategy) << " pixel " << col << "," << row;
          if (traced_inside) ++next;
          continue;
        }
        if (!traced_inside) continue;
        ++inside;
        const Vec3 uvw = traced.uvw[next++];
        // Within the residual tolerance of the pixel centre, and the global solution.
        EXPECT_LE(norm(v.evaluate(uvw) - x), params.newton.residual_tolerance_model);
        for (int d = 0; d < 3; ++d) EXPECT_NEAR(uvw[d], g.preimages.front().uvw[d], 1e-6);
      }
    }
    EXPECT_EQ(mismatched, 0);
    EXPECT_GT(inside, 5000) << to_string(strategy);
  }
}

TEST(CellTracer, EveryStrategyAgreesWithTheGlobalSolverOnWholeRows) {
  expect_agreement_with_global_solver(test::twisted_bent_box(8, 6, 5),
                                      {TracingStrategy::kPreviousPoint, TracingStrategy::kPreviousLine,
                                       TracingStrategy::kFull, TracingStrategy::kPredict, TracingStrategy::kFlood});
  // Where guesses miss and Jacobian steps settle the pixels.
  expect_agreement_with_global_solver(strongly_bent_volume(), {TracingStrategy::kPredict, TracingStrategy::kFlood});
}

// Rows traced several at a time give each pixel exactly the seeds the sequential order
// gives it, so every answer, every counter and the order of the rows handed over are the
// same for any number of rows in flight. The spans have gaps, skipped rows and lone pixels,
// so rows start, stop and wait on the row above in every way the scheduler allows.
TEST(CellTracer, RowsInFlightGiveTheSequentialAnswers) {
  const Volume v = test::twisted_bent_box(8, 6, 5);
  const GlobalSolver solver(v);
  const SliceLayout L = layout_over(v);
  const double z = 0.4 * v.bounds().lo.z + 0.6 * v.bounds().hi.z;
  detail::RowSpans spans(static_cast<std::size_t>(L.height_px));
  for (int row = 0; row < L.height_px; ++row) {
    if (row % 11 == 5) continue;  // a row without candidates: the next row has no row above
    auto& s = spans[static_cast<std::size_t>(row)];
    const int w = L.width_px;
    if (row % 7 == 3) {
      // Gaps of 2 to 6 columns, one span empty, one beyond the row above's reach.
      s = {{0, w / 3},
           {w / 3 + 2 + row % 5, w / 2},
           {w / 2 + 5, w / 2 + 1},
           {w / 2 + 3 + detail::CellTracer::kFloodReach, w - 1}};
    } else if (row % 13 == 0) {
      s = {{w / 2, w / 2}};  // one pixel
    } else {
      s = {{0, w - 1}};
    }
  }
  struct Run {
    std::vector<int> order;
    std::vector<detail::TracedRow> rows;
    TraceCounters counters;
    std::int64_t inside = 0;
  };
  auto run = [&](TracingStrategy strategy, int rows_in_flight) {
    SliceParams params;
    params.tracing = strategy;
    detail::CellTracer tracer(v, solver, params, L.width_px, rows_in_flight);
    Run out;
    tracer.trace_layer(L, z, spans, [&](int row, const detail::TracedRow& traced) {
      out.order.push_back(row);
      out.rows.push_back(traced);
    });
    out.counters = tracer.counters();
    out.inside = tracer.inside();
    return out;
  };
  for (TracingStrategy strategy : {TracingStrategy::kFull, TracingStrategy::kFlood}) {
    const Run sequential = run(strategy, 1);
    std::size_t pixels = 0;
    for (const auto& r : sequential.rows) pixels += r.cols.size();
    EXPECT_GT(pixels, 10000u);
    for (std::size_t i = 1; i < sequential.order.size(); ++i) EXPECT_LT(sequential.order[i - 1], sequential.order[i]);
    // The first pixel of the layer has no solved neighbour to start from.
    EXPECT_GE(sequential.counters.global_unseeded, 1);
    EXPECT_LE(sequential.counters.global_unseeded, sequential.counters.global_calls);
    for (int in_flight : {2, 4, 7}) {
      const Run r = run(strategy, in_flight);
      EXPECT_EQ(r.order, sequential.order) << in_flight;
      ASSERT_EQ(r.rows.size(), sequential.rows.size());
      for (std::size_t i = 0; i < r.rows.size(); ++i) {
        EXPECT_EQ(r.rows[i].cols, sequential.rows[i].cols) << "row " << r.order[i];
        ASSERT_EQ(r.rows[i].uvw.size(), sequential.rows[i].uvw.size());
        for (std::size_t k = 0; k < r.rows[i].uvw.size(); ++k)
          for (int d = 0; d < 3; ++d) ASSERT_EQ(r.rows[i].uvw[k][d], sequential.rows[i].uvw[k][d]);
      }
      EXPECT_EQ(r.counters.candidates, sequential.counters.candidates);
      EXPECT_EQ(r.inside, sequential.inside);
      EXPECT_EQ(r.counters.newton_evals, sequential.counters.newton_evals);
      EXPECT_EQ(r.counters.global_calls, sequential.counters.global_calls);
      EXPECT_EQ(r.counters.global_unseeded, sequential.counters.global_unseeded);
    }
  }
}

// A guess that misses is settled by the Jacobian step from it: one evaluation of V and J and
// the Newton step certified by Taylor's remainder (a polynomial volume), or the step's end
// checked by one value in the next batch (a rational one, which has no such bound), never
// the slow path. Every pixel still meets the residual tolerance.
TEST(CellTracer, MissedGuessesAreSettledByTheirJacobianSteps) {
  SliceParams params;
  params.tracing = TracingStrategy::kFlood;
  const double tol = params.newton.residual_tolerance_model;
  struct Case {
    const char* name;
    Volume volume;
    double z;
  };
  for (const Case& k : {Case{"quadratic, bent", strongly_bent_volume(), 1.5},
                        Case{"rational annulus", test::annulus_sector(2.0, 10.0, 1.0), 0.5}}) {
    const Volume& v = k.volume;
    const GlobalSolver solver(v);
    const SliceLayout L = layout_over(v);
    const detail::RowSpans inside = inside_spans(v, solver, params, L, k.z);
    detail::CellTracer tracer(v, solver, params, L.width_px);
    std::int64_t pixels = 0, beyond_tolerance = 0;
    tracer.trace_layer(L, k.z, inside, [&](int, const detail::TracedRow& traced) {
      pixels += static_cast<std::int64_t>(traced.cols.size());
      for (std::size_t i = 0; i < traced.cols.size(); ++i)
        if (norm(v.evaluate(traced.uvw[i]) - traced.xyz[i]) > tol) ++beyond_tolerance;
    });
    const TraceCounters& c = tracer.counters();
    ASSERT_GT(pixels, 5000) << k.name;
    EXPECT_EQ(tracer.inside(), pixels) << k.name;
    EXPECT_EQ(beyond_tolerance, 0) << k.name;
    EXPECT_GT(c.guess_misses, 20) << k.name;
    // Each miss takes a Jacobian step, and so do the next few pixels and each span's first.
    EXPECT_GT(c.jacobian_steps, c.guess_misses) << k.name;
    // The slow path only for the pixels next to no solved one (the first of the layer, which
    // the global solver settles, and a few that start from a farther pixel of the row
    // above), and for a rational volume's checked steps that miss, now and then, where the
    // inverse bends fastest.
    EXPECT_EQ(c.global_calls, c.global_unseeded) << k.name;
    EXPECT_LT(c.slow_path_pixels, c.guess_misses / 4) << k.name;
    EXPECT_LE(static_cast<double>(c.newton_evals) / static_cast<double>(pixels), 1.25) << k.name;
  }
}

}  // namespace
}  // namespace trivox
