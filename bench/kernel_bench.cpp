// Kernel figures for docs/PERFORMANCE.md: evaluation, warm-started inversion and global
// solves on a cubic 8x8x8 trivariate (the twisted, bent 40 x 30 x 60 mm test column), and
// Floyd-Steinberg dithering of one layer.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "support/test_support.h"
#include "trivox/inverse/invert.h"
#include "trivox/raster/dither.h"

namespace {

using trivox::Vec3;

const trivox::Volume& column() {
  static const trivox::Volume v = trivox::test::twisted_bent_box(40, 30, 60, 8, 4);
  return v;
}

// The same column evaluated by the de Boor kernel, for the side-by-side ratio.
const trivox::Volume& column_de_boor() {
  static const trivox::Volume v = [] {
    trivox::VolumeOptions options;
    options.power_form = false;
    return trivox::Volume(column().spline(), options);
  }();
  return v;
}

std::vector<Vec3> random_params(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Vec3> out(static_cast<std::size_t>(n));
  for (Vec3& t : out) t = {U(rng), U(rng), U(rng)};
  return out;
}

// Argument 0: the default kernel (power form); 1: the de Boor kernel.
const trivox::Volume& column_for(const benchmark::State& state) {
  return state.range(0) == 0 ? column() : column_de_boor();
}

void BM_Evaluate(benchmark::State& state) {
  const trivox::Volume& v = column_for(state);
  const auto params = random_params(4096, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(v.evaluate(params[i++ & 4095]));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Evaluate)->ArgName("de_boor")->Arg(0)->Arg(1);

void BM_EvaluateJacobian(benchmark::State& state) {
  const trivox::Volume& v = column_for(state);
  const auto params = random_params(4096, 2);
  std::size_t i = 0;
  Vec3 p;
  trivox::Mat3 J;
  for (auto _ : state) {
    v.evaluate_jacobian(params[i++ & 4095], p, J);
    benchmark::DoNotOptimize(p);
    benchmark::DoNotOptimize(J);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EvaluateJacobian)->ArgName("de_boor")->Arg(0)->Arg(1);

// Values along rows, as the slicer's tracer evaluates its row guesses: each row a dependent
// chain (the next parameter waits on the row's last value). Argument 0: one row, the old
// tracer's order; 1: four rows, each point with Volume::evaluate; 2: four rows, their points
// handed to Volume::evaluate_many together, as the tracer does; 3 and 4: values and
// Jacobians (the tracer's Jacobian steps), four rows point by point with
// Volume::evaluate_jacobian, and together with Volume::evaluate_jacobian_many. Same values.
void BM_EvaluateRowChains(benchmark::State& state) {
  const trivox::Volume& v = column();
  // Each row a straight walk through the domain in 256 steps, between random ends.
  const auto ends = random_params(8, 5);
  std::vector<Vec3> params(4 * 256);
  for (std::size_t r = 0; r < 4; ++r)
    for (std::size_t i = 0; i < 256; ++i)
      params[r * 256 + i] = ends[2 * r] + (static_cast<double>(i) / 255.0) * (ends[2 * r + 1] - ends[2 * r]);
  const int mode = static_cast<int>(state.range(0));
  const std::size_t rows = mode == 0 ? 1 : 4;
  std::int64_t points = 0;
  for (auto _ : state) {
    Vec3 last[4] = {};
    trivox::Mat3 jacobians[4];
    for (std::size_t i = 0; i < 256; ++i) {
      Vec3 at[4];
      for (std::size_t r = 0; r < rows; ++r) at[r] = params[r * 256 + i] + 1e-30 * last[r];
      if (mode == 2) {
        v.evaluate_many(at, last);
      } else if (mode == 3) {
        for (std::size_t r = 0; r < rows; ++r) v.evaluate_jacobian(at[r], last[r], jacobians[r]);
      } else if (mode == 4) {
        v.evaluate_jacobian_many(at, last, jacobians);
      } else {
        for (std::size_t r = 0; r < rows; ++r) last[r] = v.evaluate(at[r]);
      }
    }
    benchmark::DoNotOptimize(last);
    benchmark::DoNotOptimize(jacobians);
    points += static_cast<std::int64_t>(rows * 256);
  }
  state.SetItemsProcessed(points);
}
BENCHMARK(BM_EvaluateRowChains)->ArgName("mode")->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

// A row of pixels 0.04 mm apart along x, each inverted with the previous pixel's solution
// as the hint, as the slicer's tracing does.
void BM_WarmInversion(benchmark::State& state) {
  const trivox::Volume& v = column();
  const trivox::GlobalSolver solver(v);
  const Vec3 start = v.evaluate({0.2, 0.5, 0.5});
  const int n = 500;  // 20 mm of row
  std::vector<Vec3> row(n);
  for (int i = 0; i < n; ++i) row[static_cast<std::size_t>(i)] = start + Vec3{0.04 * i, 0, 0};
  const Vec3 first = solver.solve(row[0]).preimages.at(0).uvw;
  std::int64_t points = 0, iterations = 0;
  for (auto _ : state) {
    Vec3 hint = first;
    for (const Vec3& x : row) {
      const trivox::InverseResult r = trivox::invert(v, x, hint);
      hint = r.uvw;
      iterations += r.iterations;
      benchmark::DoNotOptimize(r);
    }
    points += n;
  }
  state.SetItemsProcessed(points);
  state.counters["evals_per_point"] = static_cast<double>(iterations) / static_cast<double>(points);
}
BENCHMARK(BM_WarmInversion);

// The same row with the slicer's fast path: prediction from the neighbour's Jacobian, one
// Newton step, a value-only check.
void BM_WarmInversionPredicted(benchmark::State& state) {
  const trivox::Volume& v = column();
  const trivox::GlobalSolver solver(v);
  const Vec3 start = v.evaluate({0.2, 0.5, 0.5});
  const int n = 500;
  std::vector<Vec3> row(n);
  for (int i = 0; i < n; ++i) row[static_cast<std::size_t>(i)] = start + Vec3{0.04 * i, 0, 0};
  trivox::NeighbourSolution first{solver.solve(row[0]).preimages.at(0).uvw, row[0], {}};
  Vec3 p;
  v.evaluate_jacobian(first.uvw, p, first.jacobian);
  std::int64_t points = 0, evaluations = 0;
  for (auto _ : state) {
    trivox::NeighbourSolution seed = first;
    for (const Vec3& x : row) {
      trivox::Mat3 J;
      const trivox::InverseResult r = trivox::invert_from_neighbour(v, x, seed, {}, &J);
      seed = {r.uvw, x, J};
      evaluations += r.iterations;
      benchmark::DoNotOptimize(r);
    }
    points += n;
  }
  state.SetItemsProcessed(points);
  state.counters["evals_per_point"] = static_cast<double>(evaluations) / static_cast<double>(points);
}
BENCHMARK(BM_WarmInversionPredicted);

void BM_GlobalSolve(benchmark::State& state) {
  const trivox::Volume& v = column();
  const trivox::GlobalSolver solver(v);
  const auto params = random_params(1024, 3);
  std::vector<Vec3> points;
  for (const Vec3& t : params) points.push_back(v.evaluate(t));
  std::size_t i = 0;
  std::int64_t boxes = 0;
  for (auto _ : state) {
    const trivox::GlobalResult r = solver.solve(points[i++ & 1023]);
    boxes += r.boxes_visited;
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["boxes_per_solve"] = static_cast<double>(boxes) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_GlobalSolve);

// Points 0.01 mm outside the side face u = 1 of the column (twisted, so slanted), as the slicer meets them in
// the band along a cell's outline: the solver must prove there is no preimage. Argument 1
// passes the face normal as the separating-plane hint (what the slicer does), 0 does not.
void BM_GlobalSolveJustOutside(benchmark::State& state) {
  const trivox::Volume& v = column();
  const trivox::GlobalSolver solver(v);
  const auto params = random_params(256, 4);
  std::vector<Vec3> points, normals;
  for (const Vec3& t : params) {
    Vec3 p;
    trivox::Mat3 J;
    v.evaluate_jacobian({1.0, t.y, t.z}, p, J);
    Vec3 n = trivox::cross(J.column(1), J.column(2));
    if (trivox::dot(n, J.column(0)) < 0) n = -1.0 * n;
    n = (1.0 / trivox::norm(n)) * n;
    points.push_back(p + 0.01 * n);
    normals.push_back(n);
  }
  std::size_t i = 0;
  std::int64_t boxes = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & 255;
    const trivox::GlobalResult r = state.range(0) ? solver.solve(points[k], {}, normals[k]) : solver.solve(points[k]);
    if (r.status != trivox::GlobalStatus::kNone) state.SkipWithError("a point outside was not proved outside");
    boxes += r.boxes_visited;
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["boxes_per_solve"] = static_cast<double>(boxes) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_GlobalSolveJustOutside)->ArgName("hint")->Arg(0)->Arg(1);

// Floyd-Steinberg on a 2000 x 1000 layer of one to three materials: an elliptic part filling
// most of the layer (the rest outside), graded in both directions, so that the error is never
// zero.
// Argument: the number of materials (1 to 3). Items are inside pixels.
void BM_DitherFloydSteinberg(benchmark::State& state) {
  const int w = 2000, h = 1000, m = static_cast<int>(state.range(0));
  trivox::MaterialGrid grid(w, h, m);
  trivox::InsideMask inside(w, h);
  std::int64_t inside_pixels = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double a = (x - 0.5 * w) / (0.48 * w), b = (y - 0.5 * h) / (0.48 * h);
      if (a * a + b * b > 1.0) continue;
      inside.at(x, y) = 1;
      ++inside_pixels;
      for (int j = 0; j < m; ++j) grid.at(x, y, j) = static_cast<float>((0.2 + 0.6 * x / w + 0.1 * j * y / h) / m);
    }
  trivox::LabelImage labels;
  int layer = 0;
  for (auto _ : state) {
    trivox::dither(grid, inside, {}, labels, layer++);
    benchmark::DoNotOptimize(labels.values().data());
  }
  state.SetItemsProcessed(state.iterations() * inside_pixels);
}
BENCHMARK(BM_DitherFloydSteinberg)->ArgName("materials")->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
