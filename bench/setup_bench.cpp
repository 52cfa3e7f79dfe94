// What `trivox slice` does before its first layer (docs/PERFORMANCE.md, "Set-up"), step by
// step, on the paper's duck (examples/shared_scenes/duck.json: the untangled Coons volume of
// the G+Smo duck's six faces) or any scene:
//  * reading the scene: without the construction cache (a first run, or --no-cache), with an
//    empty cache (the volume is built and stored), and with the cache holding the volume (a
//    repeated run, --resume, another shard);
//  * the slicer's set-up: the Bezier pieces of each volume for the global solver, the tight
//    bounds, the outline meshes;
//  * the job's estimate from one sample layer (skipped with --no-checks).
// Each step is repeated and its median wall and CPU times printed; the machine's load shows as
// wall time above CPU time.
//
//   setup_bench [--scene PATH] [--repeat N]
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_support.h"
#include "trivox/job/job.h"
#include "trivox/job/job_estimate.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

using namespace trivox;

namespace {

struct Times {
  double wall = 0, cpu = 0;
};

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

Times timed(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = process_cpu_seconds();
  f();
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), process_cpu_seconds() - c0};
}

Times median(std::vector<Times> t) {
  std::sort(t.begin(), t.end(), [](const Times& a, const Times& b) { return a.wall < b.wall; });
  return t[t.size() / 2];
}

std::string arg_text(int argc, char** argv, const char* name, std::string fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == name) return argv[i + 1];
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path scene_path = arg_text(
      argc, argv, "--scene", (std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes" / "duck.json").string());
  const int repeat = std::max(1, bench::arg_int(argc, argv, "--repeat", 3));
  const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "trivox-setup-bench";
  std::filesystem::remove_all(scratch);

  std::vector<Times> plain, miss, hit, slicer_t, estimate_t;
  std::string cells;
  for (int r = 0; r < repeat; ++r) {
    plain.push_back(timed([&] { read_scene(scene_path); }));
    std::filesystem::remove_all(scratch);
    ConstructionCache empty(construction_cache_dir(scratch));
    miss.push_back(timed([&] { read_scene(scene_path, SceneReadOptions{nullptr, &empty}); }));
    ConstructionCache filled(construction_cache_dir(scratch));
    std::optional<Scene> scene;
    hit.push_back(timed([&] { scene.emplace(read_scene(scene_path, SceneReadOptions{nullptr, &filled})); }));
    if (filled.hits() == 0 && empty.stored() > 0) {
      fmt::print(stderr, "the cache did not return what it stored\n");
      return 1;
    }
    cells = fmt::format("{} cells, {} volumes built and cached", scene->cells.size(), empty.stored());
    std::optional<Slicer> slicer;
    slicer_t.push_back(timed([&] { slicer.emplace(*scene, SliceParams{}); }));
    JobParams job;
    job.output_dir = scratch;
    const int middle = slicer->layout().num_layers / 2;
    job.first_layer = job.last_layer = middle;
    estimate_t.push_back(timed([&] { estimate_job(*slicer, job, EstimateParams{1}); }));
  }
  std::filesystem::remove_all(scratch);

  fmt::print("{}: {}; median of {} runs\n", scene_path.string(), cells, repeat);
  fmt::print("{:<52} {:>8} {:>8}\n", "step", "wall s", "CPU s");
  const auto row = [](const char* what, const std::vector<Times>& t) {
    const Times m = median(t);
    fmt::print("{:<52} {:>8.3f} {:>8.3f}\n", what, m.wall, m.cpu);
    return m;
  };
  const Times p = row("read the scene, no cache (a first run, --no-cache)", plain);
  row("read the scene, empty cache (build and store)", miss);
  const Times h = row("read the scene, cache holds the volumes", hit);
  const Times s = row("slicer set-up (pieces, bounds, outline meshes)", slicer_t);
  const Times e = row("estimate from one sample layer", estimate_t);
  fmt::print("{:<52} {:>8.3f} {:>8.3f}\n", "before the first layer, first run", p.wall + s.wall + e.wall,
             p.cpu + s.cpu + e.cpu);
  fmt::print("{:<52} {:>8.3f} {:>8.3f}\n", "before the first layer, volumes cached", h.wall + s.wall + e.wall,
             h.cpu + s.cpu + e.cpu);
  return 0;
}
