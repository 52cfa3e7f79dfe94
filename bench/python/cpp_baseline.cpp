// The C++ side of bench/python/api_bench.py: the library's bulk calls on the same points the
// Python benchmark passes to the module, timed in the same run (docs/PERFORMANCE.md,
// "Python API").
//
//   trivox_python_baseline MODEL TRIVARIATE MODE THREADS REPEATS POINTS.f64 [LOOPS]
//
// MODE: evaluate (Volume::evaluate_many), jacobian (evaluate_jacobian_many), invert (invert()
// from the domain's centre, point by point). THREADS: 1 runs the points on this thread; 0 or
// more share them among workers in chunks of 4096 points (parallel_for_each), as the module
// does. Each repeat runs the call LOOPS times (default 1: small batches need many to be timed).
// Prints one JSON line: {"mode", "threads", "points", "loops", "seconds": [wall time per call,
// one per repeat], "cpu_seconds": [the same in CPU time of this thread; with THREADS 1 the
// whole work, unaffected by other programs' load]}.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "trivox/inverse/invert.h"
#include "trivox/io/model.h"
#include "trivox/parallel.h"
#include "trivox/spline/volume.h"

namespace {

constexpr std::size_t kChunk = 4096;

std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6e", s);
  return text;
}

// CPU time of the calling thread (s): the work of a one-thread run, whatever else runs.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void for_chunks(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t)>& body) {
  if (threads == 1) {
    for (std::size_t b = 0; b < n; b += kChunk) body(b, std::min(n, b + kChunk));
    return;
  }
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  trivox::parallel_for_each(chunks, threads, [&](std::size_t c) { body(c * kChunk, std::min(n, (c + 1) * kChunk)); });
}

}  // namespace

int main(int argc, char** argv) {
  using namespace trivox;
  if (argc != 7 && argc != 8) {
    std::fprintf(stderr, "usage: %s MODEL TRIVARIATE MODE THREADS REPEATS POINTS.f64 [LOOPS]\n", argv[0]);
    return 2;
  }
  try {
    const Model model = read_model(argv[1]);
    const auto index = static_cast<std::size_t>(std::stoi(argv[2]));
    const Volume volume(model.patches.at(static_cast<std::size_t>(model.volume_indices().at(index))).spline);
    const std::string mode = argv[3];
    const int threads = std::stoi(argv[4]);
    const int repeats = std::stoi(argv[5]);
    const int loops = argc == 8 ? std::stoi(argv[7]) : 1;
    std::ifstream in(argv[6], std::ios::binary);
    std::vector<Vec3> points;
    for (Vec3 p; in.read(reinterpret_cast<char*>(&p), sizeof p);) points.push_back(p);
    const std::size_t n = points.size();
    std::vector<Vec3> values(n);
    std::vector<Mat3> jacobians(n);
    std::vector<InverseResult> inverses(n);
    const Vec3 centre = volume.domain().center();
    std::function<void(std::size_t, std::size_t)> body;
    if (mode == "evaluate") {
      body = [&](std::size_t b, std::size_t e) {
        volume.evaluate_many(std::span<const Vec3>(points).subspan(b, e - b),
                             std::span<Vec3>(values).subspan(b, e - b));
      };
    } else if (mode == "jacobian") {
      body = [&](std::size_t b, std::size_t e) {
        volume.evaluate_jacobian_many(std::span<const Vec3>(points).subspan(b, e - b),
                                      std::span<Vec3>(values).subspan(b, e - b),
                                      std::span<Mat3>(jacobians).subspan(b, e - b));
      };
    } else if (mode == "invert") {
      body = [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) inverses[i] = invert(volume, points[i], centre);
      };
    } else {
      std::fprintf(stderr, "unknown mode '%s' (evaluate, jacobian, invert)\n", mode.c_str());
      return 2;
    }
    std::string seconds, cpu_seconds;
    for (int r = 0; r < repeats; ++r) {
      const double cpu0 = thread_cpu_seconds();
      const auto start = std::chrono::steady_clock::now();
      for (int l = 0; l < loops; ++l) for_chunks(n, threads, body);
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double cpu = thread_cpu_seconds() - cpu0;
      if (r > 0) seconds += ", ";
      seconds += seconds_text(s / loops);
      if (r > 0) cpu_seconds += ", ";
      cpu_seconds += seconds_text(cpu / loops);
    }
    // Something of every result, so that no work can be optimised away.
    double check = 0;
    for (std::size_t i = 0; i < n; i += 997) check += values[i].x + jacobians[i].m[0][0] + inverses[i].uvw.x;
    std::printf(
        "{\"mode\": \"%s\", \"threads\": %d, \"points\": %zu, \"loops\": %d, \"seconds\": [%s], \"cpu_seconds\": "
        "[%s], \"check\": %.17g}\n",
        mode.c_str(), threads, n, loops, seconds.c_str(), cpu_seconds.c_str(), check);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trivox_python_baseline: %s\n", e.what());
    return 1;
  }
}
