// The tracer's fast paths (row extrapolation, neighbour-predicted Newton, hinted global
// solves) against the slow reference: the global solver on every pixel of whole rows.
#include "slice/cell_tracer.h"

#include <cmath>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/slice/layout.h"

namespace trivox {
namespace {

TEST(CellTracer, EveryStrategyAgreesWithTheGlobalSolverOnWholeRows) {
  const Volume v = test::twisted_bent_box(8, 6, 5);
  const GlobalSolver solver(v);
  // A 600 x 300 dpi grid over the column's bounding rectangle.
  SliceLayout L;
  L.pitch_x_mm = 25.4 / 600;
  L.pitch_y_mm = 25.4 / 300;
  L.x0_mm = v.bounds().lo.x - 2 * L.pitch_x_mm;
  L.y_top_mm = v.bounds().hi.y + 2 * L.pitch_y_mm;
  L.width_px = static_cast<int>((v.bounds().hi.x - L.x0_mm) / L.pitch_x_mm) + 3;
  L.height_px = static_cast<int>((L.y_top_mm - v.bounds().lo.y) / L.pitch_y_mm) + 3;
  const double z = 0.5 * (v.bounds().lo.z + v.bounds().hi.z);

  for (TracingStrategy strategy : {TracingStrategy::kPreviousPoint, TracingStrategy::kPreviousLine, TracingStrategy::kFull,
                                   TracingStrategy::kPredict, TracingStrategy::kFlood}) {
    SliceParams params;
    params.tracing = strategy;
    detail::CellTracer tracer(v, solver, params, L.width_px);
    tracer.begin_layer(z);
    const std::vector<std::pair<int, int>> whole_row = {{0, L.width_px - 1}};
    int inside = 0, mismatched = 0;
    for (int row = 0; row < L.height_px; ++row) {
      detail::TracedRow traced;
      tracer.trace_row(L, row, whole_row, traced);
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

}  // namespace
}  // namespace trivox
