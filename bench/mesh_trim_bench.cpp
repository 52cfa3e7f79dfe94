// The cost of a mesh trim (docs/SCENE.md, "Mesh trims") per inside pixel, for
// docs/PERFORMANCE.md: a UV sphere of about 1e5 triangles (radius 12 mm, written as a binary
// STL) trims a box cell inscribed in it, so that the trimmed and the untrimmed cell own the
// same pixels and the difference of their times is what the trim costs.
//
//   mesh_trim_bench [--triangles N] [--layers L] [--repeats R]
// --triangles N: about N triangles in the sphere (default 100000).
// --layers L: layers sliced per run, spread over the box's middle half (default 24).
// --repeats R: runs of each case, alternating, reported as medians (default 5).
//
// Two figures:
//  * end to end: Slicer::slice_layer on one thread (outlines, inversion, material, dithering)
//    of the box untrimmed, trimmed by the even-odd rule and trimmed by the winding-number
//    rule; the trim's cost per inside pixel is the difference of the medians over the pixels;
//  * the trim's own steps, as the slicer runs them (cut_trimming_shells in layer_decision.cpp,
//    narrow_to_model_space_clauses in layer_candidates.cpp): the cut of the mesh by the layer's plane, its crossings
//    per row and the stretches of each row inside, timed alone, per inside pixel; and the
//    same with the even-odd test at every pixel instead.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "bench_support.h"
#include "mesh/mesh_fixtures.h"
#include "slice/scanline.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

using namespace trivox;
using namespace trivox::bench;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string scene_text(const fs::path& mesh, double half, const std::string& trim) {
  std::string points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        points += fmt::format("{}[{}, {}, {}]", points.empty() ? "" : ", ", i ? half : -half, j ? half : -half,
                              k ? half : -half);
  const std::string clause =
      trim.empty() ? ""
                   : fmt::format(R"(, "trim": [{{"side": "inside", "shell": {{"mesh": "{}", "inside_rule": "{}"}}}}])",
                                 mesh.string(), trim);
  return fmt::format(
      R"({{"version": 1, "units": "mm", "printer": "j750-hm", "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [{{"name": "box", "geometry": {{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [{}]}}, "material": {{"kind": "expression", "fractions": {{"VeroCyan": "u", "VeroMagenta": "1 - u"}}}}{}}}]}})",
      points, clause);
}

}  // namespace

int main(int argc, char** argv) {
  const int wanted = arg_int(argc, argv, "--triangles", 100000);
  const int layers = arg_int(argc, argv, "--layers", 24);
  const int repeats = arg_int(argc, argv, "--repeats", 5);

  // A UV sphere has 2 s (r - 1) triangles for r rings and s sectors; s = 2 r.
  const int rings = std::max(3, static_cast<int>(std::lround(std::sqrt(wanted / 4.0))));
  const double radius = 12;
  const test::TestMesh sphere = test::sphere_mesh({0, 0, 0}, radius, rings, 2 * rings);
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox_mesh_trim_bench_{}", ::getpid());
  fs::create_directories(dir);
  const fs::path stl = dir / "sphere.stl";
  test::write_bytes(stl, test::binary_stl(sphere));
  // The box's corners at 0.95 of the radius: every pixel of the box is inside the sphere.
  const double half = 0.95 * radius / std::sqrt(3.0);

  struct Case {
    const char* name;
    std::string trim;
    std::vector<double> seconds;
    std::int64_t inside = 0;
  };
  std::vector<Case> cases = {{"untrimmed", "", {}, 0},
                             {"mesh trim, even-odd", "even-odd", {}, 0},
                             {"mesh trim, winding-number", "winding-number", {}, 0}};
  std::vector<Scene> scenes;
  for (const Case& c : cases) scenes.push_back(parse_scene(scene_text(stl, half, c.trim), dir / "bench.json"));
  std::vector<std::unique_ptr<Slicer>> slicers;
  for (const Scene& s : scenes) slicers.push_back(std::make_unique<Slicer>(s, SliceParams{}));
  const SliceLayout& L = slicers[0]->layout();
  std::vector<int> picked;
  for (int i = 0; i < layers; ++i) picked.push_back(L.num_layers / 4 + (2 * i + 1) * (L.num_layers / 2) / (2 * layers));

  // Alternating, so that a change of the machine's load falls on every case alike.
  for (int r = 0; r < repeats; ++r)
    for (std::size_t c = 0; c < cases.size(); ++c) {
      std::int64_t inside = 0;
      const auto t0 = Clock::now();
      for (int layer : picked) inside += slicers[c]->slice_layer(layer).stats.pixels_inside;
      cases[c].seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      cases[c].inside = inside;
    }

  const TriangleMeshFile read = read_triangle_mesh(stl);
  fmt::print(
      "mesh: {} triangles ({} rings x {} sectors, radius {} mm); box {:.3f} mm across; {} layers of {} x {} px\n",
      read.triangles.size(), rings, 2 * rings, radius, 2 * half, layers, L.width_px, L.height_px);
  fmt::print(
      "\n| case | inside pixels | ms per run (median of {}) | ns per inside pixel | over untrimmed, ns per inside "
      "pixel |\n"
      "|---|---|---|---|---|\n",
      repeats);
  const double base = median(cases[0].seconds);
  for (const Case& c : cases) {
    const double m = median(c.seconds);
    fmt::print(
        "| {} | {} | {:.1f} | {:.1f} | {} |\n", c.name, c.inside, 1e3 * m, 1e9 * m / static_cast<double>(c.inside),
        c.trim.empty() ? std::string("") : fmt::format("{:.2f}", 1e9 * (m - base) / static_cast<double>(c.inside)));
    if (c.inside != cases[0].inside) fmt::print("  (the cases own different pixels: the box is not inside the mesh)\n");
  }

  // The trim's own steps for the same layers, as the slicer runs them: the cut, the crossings
  // per row, and the narrowing of each row's span to the stretches inside (crossing_runs);
  // then the same with the test at every pixel instead (inside_crossings: the path of rows
  // the crossings cannot decide alone, and of cells whose pixels are traced first).
  const SlicedMesh mesh(read.vertices, read.triangles);
  const std::vector<std::pair<int, int>> whole_row = {{0, L.width_px - 1}};
  std::vector<Segment2> segments;
  std::vector<std::vector<double>> rows;
  std::vector<std::pair<int, int>> runs, kept;
  for (const bool per_pixel : {false, true}) {
    std::vector<double> steps;
    std::int64_t in = 0;
    for (int r = 0; r < repeats; ++r) {
      in = 0;
      const auto t0 = Clock::now();
      for (int layer : picked) {
        mesh.cut(L.z_of_layer(layer), segments);
        detail::shell_row_crossings(segments, L, rows);
        for (int row = 0; row < L.height_px; ++row) {
          const auto& xs = rows[static_cast<std::size_t>(row)];
          if (per_pixel) {
            for (int col = 0; col < L.width_px; ++col) in += detail::inside_crossings(xs, L.x_of_col(col));
          } else {
            detail::crossing_runs(xs, nullptr, true, L, runs);
            detail::intersect_row(whole_row, runs, kept);
            for (const auto& [c0, c1] : kept) in += c1 - c0 + 1;
          }
        }
      }
      steps.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    const double s = median(steps);
    fmt::print("\nthe trim's steps alone, {}: {:.2f} ms for {} inside pixels: {:.2f} ns per inside pixel\n",
               per_pixel ? "tested per pixel" : "stretches between crossings (the slicer's narrowing)", 1e3 * s, in,
               1e9 * s / static_cast<double>(std::max<std::int64_t>(in, 1)));
  }
  fs::remove_all(dir);
  return 0;
}
