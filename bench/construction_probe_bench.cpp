// What checking a cached volume against its inputs costs beside what the cache saves
// (docs/SLICING.md, "The construction cache"), on the paper's duck: the untangled Coons volume
// of the six faces of ../shared/data/surfaces/duck_brep.xml with the settings of
// examples/shared_scenes/duck.json. BM_BuildDuck is what a cache hit saves (the construction
// and its Jacobian report); BM_LoadDuckEntry what a hit costs to read (file, SHA-256, decode);
// BM_ProbeDuck the check of the loaded volume against the six faces.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <optional>

#include "scene/construction_probe.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/untangle.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/io/model.h"
#include "trivox/scene/construction_cache.h"

namespace trivox {
namespace {

const std::filesystem::path kDuck = std::filesystem::path(TRIVOX_SHARED_DATA_DIR) / "surfaces" / "duck_brep.xml";

std::optional<std::array<TensorSpline, 6>> duck_faces() {
  if (!std::filesystem::exists(kDuck)) return std::nullopt;
  std::vector<TensorSpline> surfaces;
  for (const Patch& p : read_model(kDuck).patches)
    if (p.spline.param_dim() == 2) surfaces.push_back(p.spline);
  return arrange_cube_faces(surfaces);
}

Constructed build_duck(const std::array<TensorSpline, 6>& faces) {
  CoonsParams p;
  p.check.samples_per_direction = 33;
  UntangleParams u;
  u.knots_per_span = 1;
  u.iterations = 400;
  Volume volume(untangle(coons(faces, p).volume.spline(), u).spline);
  ConstructionReport report = inspect_volume(volume, p.check);
  return {std::move(volume), std::move(report)};
}

void BM_BuildDuck(benchmark::State& state) {
  const auto faces = duck_faces();
  if (!faces) return state.SkipWithError("needs ../shared/data/surfaces/duck_brep.xml");
  for (auto _ : state) benchmark::DoNotOptimize(build_duck(*faces));
}
BENCHMARK(BM_BuildDuck)->Unit(benchmark::kMillisecond);

void BM_LoadDuckEntry(benchmark::State& state) {
  const auto faces = duck_faces();
  if (!faces) return state.SkipWithError("needs ../shared/data/surfaces/duck_brep.xml");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "trivox-probe-bench";
  ConstructionCache cache(dir);
  const std::string key = sha256_hex("duck");
  cache.store(key, build_duck(*faces));
  for (auto _ : state) benchmark::DoNotOptimize(cache.load(key));
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_LoadDuckEntry)->Unit(benchmark::kMillisecond);

void BM_ProbeDuck(benchmark::State& state) {
  const auto faces = duck_faces();
  if (!faces) return state.SkipWithError("needs ../shared/data/surfaces/duck_brep.xml");
  const Constructed built = build_duck(*faces);
  if (const auto problem = detail::probe_coons(built.volume, *faces)) return state.SkipWithError(problem->c_str());
  for (auto _ : state) benchmark::DoNotOptimize(detail::probe_coons(built.volume, *faces));
}
BENCHMARK(BM_ProbeDuck)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace trivox

BENCHMARK_MAIN();
