// Warm inversion on a large volume (docs/PERFORMANCE.md, "Large volumes"): Newton from the
// neighbour's solution (invert) and the slicer's fast path (invert_from_neighbour: a
// prediction from the neighbour's Jacobian, one Newton step, its remainder bounded) along
// rows of points 0.04 mm apart, on the cubic 8 x 8 x 8 test
// column (5 x 5 x 5 pieces, a 32 KB power-form table) and on the paper's duck
// (examples/shared_scenes/duck.json: quadratic, 14 x 22 x 34 control points, 12 x 20 x 32
// pieces, a 6.6 MB table that no longer fits the caches), each with the power form and with
// the de Boor kernel. The duck needs ../shared (its benchmarks are skipped without it).
//
// Each row is a dependent chain (every point seeded by the one before), so the figure is a
// latency; rows are straight lines along x through the volume's middle, and only their
// points with a unique preimage are kept.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/scene/scene.h"

namespace {

using trivox::Vec3;

struct Subject {
  std::string missing;  // why the volume could not be made (the duck without ../shared)
  std::optional<trivox::Volume> power, de_boor;
  std::vector<std::vector<Vec3>> rows;  // runs of consecutive points that lie in the volume
};

trivox::Volume with_kernel(const trivox::Volume& v, bool power_form) {
  trivox::VolumeOptions options;
  options.power_form = power_form;
  return trivox::Volume(v.spline(), options);
}

// Rows along x at 0.04 mm spacing through the points V(0.5, v, w) on a 4 x 4 grid of (v, w),
// split where a point has no unique preimage.
std::vector<std::vector<Vec3>> rows_through(const trivox::Volume& v) {
  const trivox::GlobalSolver solver(v);
  const double width = v.bounds().size().x;
  std::vector<std::vector<Vec3>> rows;
  for (double sv : {0.2, 0.4, 0.6, 0.8})
    for (double sw : {0.2, 0.4, 0.6, 0.8}) {
      const Vec3 mid = v.evaluate({0.5, sv, sw});
      std::vector<Vec3> run;
      for (double dx = -0.5 * width; dx <= 0.5 * width; dx += 0.04) {
        const Vec3 x = mid + Vec3{dx, 0, 0};
        if (solver.solve(x).status == trivox::GlobalStatus::kUnique) {
          run.push_back(x);
        } else if (!run.empty()) {
          if (run.size() >= 16) rows.push_back(run);
          run.clear();
        }
      }
      if (run.size() >= 16) rows.push_back(run);
    }
  return rows;
}

Subject make_subject(const trivox::Volume& v) {
  Subject s{{}, with_kernel(v, true), with_kernel(v, false), {}};
  s.rows = rows_through(*s.power);
  return s;
}

const Subject& column() {
  static const Subject s = make_subject(trivox::test::twisted_bent_box(40, 30, 60, 8, 4));
  return s;
}

const Subject& duck() {
  static const Subject s = [] {
    const std::filesystem::path scene = std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes" / "duck.json";
    if (!std::filesystem::exists(std::filesystem::path(TRIVOX_SHARED_DATA_DIR)))
      return Subject{"../shared/data is absent: the duck's benchmarks need it", {}, {}, {}};
    const trivox::Scene sc = trivox::read_scene(scene);
    return make_subject(sc.cells.at(0).volume);
  }();
  return s;
}

// Arguments: duck (0 the cubic column, 1 the duck), de_boor (0 the power form, 1 the de
// Boor kernel), predicted (0: invert() from the neighbour's solution, Newton to convergence;
// 1: invert_from_neighbour(), the slicer's fast path).
void BM_WarmInversion(benchmark::State& state) {
  const Subject& s = state.range(0) == 0 ? column() : duck();
  if (!s.missing.empty()) {
    state.SkipWithError(s.missing.c_str());
    return;
  }
  const trivox::Volume& v = state.range(1) == 0 ? *s.power : *s.de_boor;
  const bool predicted = state.range(2) != 0;
  // Each row's first point from the global solver, outside the timing.
  std::vector<trivox::NeighbourSolution> firsts;
  const trivox::GlobalSolver solver(v);
  for (const auto& row : s.rows) {
    trivox::NeighbourSolution first{solver.solve(row[0]).preimages.at(0).uvw, row[0], {}};
    Vec3 p;
    v.evaluate_jacobian(first.uvw, p, first.jacobian);
    firsts.push_back(first);
  }
  std::int64_t points = 0, evaluations = 0, failed = 0;
  for (auto _ : state) {
    for (std::size_t r = 0; r < s.rows.size(); ++r) {
      trivox::NeighbourSolution seed = firsts[r];
      for (std::size_t i = 1; i < s.rows[r].size(); ++i) {
        const Vec3 x = s.rows[r][i];
        trivox::Mat3 J;
        const trivox::InverseResult res =
            predicted ? trivox::invert_from_neighbour(v, x, seed, {}, &J) : trivox::invert(v, x, seed.uvw);
        seed = {res.uvw, x, J};
        evaluations += res.iterations;
        failed += res.status != trivox::InverseStatus::kConverged;
        benchmark::DoNotOptimize(res);
      }
      points += static_cast<std::int64_t>(s.rows[r].size()) - 1;
    }
  }
  state.SetItemsProcessed(points);
  state.counters["evals_per_point"] = static_cast<double>(evaluations) / static_cast<double>(points);
  state.counters["not_converged"] = static_cast<double>(failed) / static_cast<double>(points);
  state.counters["rows"] = static_cast<double>(s.rows.size());
}
BENCHMARK(BM_WarmInversion)->ArgNames({"duck", "de_boor", "predicted"})->ArgsProduct({{0, 1}, {0, 1}, {0, 1}});

}  // namespace

BENCHMARK_MAIN();
