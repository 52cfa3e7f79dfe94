// Scaling figures for docs/PERFORMANCE.md (issue: speed, section 3):
//  * time grows linearly with the inside voxels: the duck-class model at three sizes, so
//    the same bitmap pitch sees 1x, 4x and 16x the inside voxels per layer; ns per inside
//    voxel should stay flat;
//  * memory stays flat in the number of layers: whole jobs (slicing, dithering and PNG
//    files) of three heights, each in a child process whose peak resident memory is read
//    back with wait4;
//  * the whole duck-class job on all threads, projected from a run of its middle layers.
//
//   job_scaling_bench [--threads N] [--sample-layers K]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "bench_support.h"
#include "trivox/job/job.h"
#include "trivox/slice/slicer.h"

using namespace trivox;
using namespace trivox::bench;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::filesystem::path scratch(const char* name) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Runs a job over layers [first, first + count) in a child process; returns its wall time
// and peak resident memory (MiB), or a negative time when the child failed.
std::pair<double, double> job_in_child(double scale, int first, int count, int threads) {
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    try {
      const Scene scene = duck_class_scene(scale);
      const Slicer slicer(scene, {});
      JobParams job;
      job.output_dir = scratch("trivox-job-scaling-bench");
      job.first_layer = first;
      job.last_layer = first + count - 1;
      job.threads = threads;
      job.min_layers = 0;
      run_slice_job(slicer, job);
      std::filesystem::remove_all(job.output_dir);
      std::_Exit(0);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "job failed: %s\n", e.what());
      std::_Exit(1);
    }
  }
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  const double wall = seconds_since(t0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return {-1.0, 0.0};
  return {wall, static_cast<double>(usage.ru_maxrss) / 1024.0};
}

}  // namespace

int main(int argc, char** argv) {
  const int hw = static_cast<int>(std::thread::hardware_concurrency());
  const int threads = arg_int(argc, argv, "--threads", hw > 0 ? hw : 1);
  const int sample = arg_int(argc, argv, "--sample-layers", 8);

  fmt::print(
      "Time against inside voxels (one thread, {} layers spread over the height, PNG writing "
      "excluded)\n\n",
      sample);
  fmt::print(
      "| model scale | bitmap | inside voxels per layer | time per layer [s] | ns per inside voxel |\n"
      "|---|---|---|---|---|\n");
  for (double scale : {0.25, 0.5, 1.0}) {
    const Scene scene = duck_class_scene(scale);
    const Slicer slicer(scene, {});
    const SliceLayout& L = slicer.layout();
    double seconds = 0;
    std::int64_t inside = 0;
    for (int i = 0; i < sample; ++i) {
      const LayerResult r = slicer.slice_layer(static_cast<int>((i + 0.5) * L.num_layers / sample));
      seconds += r.stats.seconds;
      inside += r.stats.pixels_inside;
    }
    fmt::print("| {} | {} x {} | {:.0f} | {:.3f} | {:.0f} |\n", scale, L.width_px, L.height_px,
               static_cast<double>(inside) / sample, seconds / sample, 1e9 * seconds / static_cast<double>(inside));
  }

  fmt::print(
      "\nMemory against layers (whole jobs with Voxel Print PNGs, model scale 0.25, {} threads, "
      "each job in its own process)\n\n",
      threads);
  fmt::print("| layers | wall time [s] | peak resident memory [MiB] |\n|---|---|---|\n");
  for (int count : {25, 50, 100}) {
    const auto [wall, mib] = job_in_child(0.25, 0, count, threads);
    if (wall < 0) return 1;
    fmt::print("| {} | {:.2f} | {:.1f} |\n", count, wall, mib);
  }

  fmt::print(
      "\nThe whole duck-class job (scale 1) on {} threads, projected from {} consecutive middle layers "
      "run as one job\n\n",
      threads, sample);
  {
    const Scene scene = duck_class_scene(1.0);
    const Slicer slicer(scene, {});
    const int layers = slicer.layout().num_layers;
    // `sample` consecutive layers from the middle, as a job (threads share them).
    const auto [wall, mib] = job_in_child(1.0, layers / 2, sample, threads);
    if (wall < 0) return 1;
    fmt::print(
        "| layers | sample wall time [s] | projected whole job [min] | peak memory [MiB] |\n|---|---|---|---|\n");
    fmt::print("| {} | {:.2f} | {:.1f} | {:.0f} |\n", layers, wall, wall / sample * layers / 60.0, mib);
  }
  return 0;
}
