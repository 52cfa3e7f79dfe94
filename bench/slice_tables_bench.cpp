// The paper's Tables 1 and 2 for a duck-class job, printed as Markdown rows for
// docs/PERFORMANCE.md. The duck itself needs the volume constructors of a later release; this
// job uses the analytic stand-in the issue names: a cubic 8x8x8 trivariate, bent and twisted,
// filling a box of 128 x 128 x 88 mm, with the porous-tiles material, at 600 x 300 dpi and
// 30 um layers (Stratasys J750, the paper's settings).
//
//   slice_tables_bench [--layers N] [--table1-scale S] [--table2-only] [--tolerance-mm T]
// --layers N: Table 2 slices N layers spread evenly over the height (default 9) and reports
//             per-layer figures and the projected total for all layers.
// --table1-scale S: Table 1 runs on the same model scaled by S (default 0.25) so that the
//             "none" row (a global solve per pixel) finishes in seconds.
// --table2-only: skip Table 1 (for profiling the production path alone).
// --tolerance-mm T: Table 2's residual tolerance (default: the slicer's default).
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_support.h"
#include "trivox/output/layer_writer.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/slice/slicer.h"

using namespace trivox;
using namespace trivox::bench;

int main(int argc, char** argv) {
  const int layers = arg_int(argc, argv, "--layers", 9);
  const double t1_scale = arg_double(argc, argv, "--table1-scale", 0.25);

  const bool table1 = !has_flag(argc, argv, "--table2-only");
  const double tolerance_mm = arg_double(argc, argv, "--tolerance-mm", SliceParams{}.newton.residual_tolerance_model);

  // Table 1: one middle layer, each strategy, single thread.
  if (table1) {
    const Scene scene = duck_class_scene(t1_scale);
    fmt::print("Table 1 (model scaled by {}; middle layer; one thread)\n\n", t1_scale);
    fmt::print(
        "| tracing | time [s] | time / previous-point | global solves [% of inside voxels] | evaluations per inside "
        "voxel | inside voxels |\n"
        "|---|---|---|---|---|---|\n");
    struct Row {
      TracingStrategy tracing;
      LayerStats stats;
    };
    std::vector<Row> rows;
    for (TracingStrategy t : {TracingStrategy::kNone, TracingStrategy::kPreviousPoint, TracingStrategy::kPreviousLine,
                              TracingStrategy::kFull, TracingStrategy::kPredict, TracingStrategy::kFlood}) {
      SliceParams p;
      p.tracing = t;
      const Slicer slicer(scene, p);
      rows.push_back({t, slicer.slice_layer(slicer.layout().num_layers / 2).stats});
    }
    const double previous_point = rows[1].stats.seconds;
    for (const Row& r : rows) {
      const auto inside = static_cast<double>(r.stats.pixels_inside);
      fmt::print("| {} | {:.3f} | {:.2f} | {:.4f} | {:.2f} | {} |\n", to_string(r.tracing), r.stats.seconds,
                 r.stats.seconds / previous_point, 100.0 * static_cast<double>(r.stats.global_calls) / inside,
                 static_cast<double>(r.stats.newton_evals) / inside, r.stats.pixels_inside);
    }
  }

  // Table 2: full size, sampled layers, single thread, the default tracing.
  {
    const Scene scene = duck_class_scene(1.0);
    const auto setup_start = std::chrono::steady_clock::now();
    SliceParams table2_params;
    table2_params.newton.residual_tolerance_model = tolerance_mm;
    const Slicer slicer(scene, table2_params);
    const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    const SliceLayout& L = slicer.layout();
    // The Voxel Print writer as a job uses it (PNG encoding, fsync, rename), into a scratch folder.
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "trivox-slice-tables-bench";
    std::filesystem::create_directories(out);
    OutputContext ctx;
    ctx.dir = out;
    for (const MaterialDef& m : scene.materials) {
      ctx.material_names.push_back(m.name);
      ctx.material_rgba.push_back(m.rgba);
    }
    ctx.total_layers = L.num_layers;
    const auto writer = make_layer_writer("voxelprint", ctx);
    LayerStats sum;
    double write_seconds = 0;
    for (int i = 0; i < layers; ++i) {
      const int layer = static_cast<int>((i + 0.5) * L.num_layers / layers);
      const LayerResult r = slicer.slice_layer(layer);
      const auto write_start = std::chrono::steady_clock::now();
      writer->write_layer(i, r.labels);
      write_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
      sum += r.stats;
    }
    std::filesystem::remove_all(out);
    sum.seconds += write_seconds;
    const double per_layer = sum.seconds / layers;
    const double inside_per_layer = static_cast<double>(sum.pixels_inside) / layers;
    const double ns = 1e9 / static_cast<double>(sum.pixels_inside);
    fmt::print("\nTable 2 (full size; {} layers sampled evenly; one thread; {} tracing; PNG writing included)\n\n",
               layers, to_string(table2_params.tracing));
    fmt::print(
        "| bitmap | layers | voxels total, inside [x1e9] (projected) | time per layer [s] | total, 1 thread [h] "
        "(projected) | global solves [%] |\n|---|---|---|---|---|---|\n");
    fmt::print("| {} x {} | {} | {:.2f}, {:.2f} | {:.3f} | {:.3f} | {:.4f} |\n", L.width_px, L.height_px, L.num_layers,
               static_cast<double>(L.width_px) * L.height_px * L.num_layers / 1e9,
               inside_per_layer * L.num_layers / 1e9, per_layer, per_layer * L.num_layers / 3600.0,
               100.0 * static_cast<double>(sum.global_calls) / static_cast<double>(sum.pixels_inside));
    fmt::print(
        "\nns per inside voxel (one core): total {:.0f} = inverse {:.0f} + material {:.0f} + dither {:.0f} + "
        "writing {:.0f}; Newton evaluations per inside voxel {:.2f}; setup (outline meshes, solver) {:.2f} s\n",
        sum.seconds * ns, sum.seconds_inverse * ns, sum.seconds_material * ns, sum.seconds_dither * ns,
        write_seconds * ns, static_cast<double>(sum.newton_evals) / static_cast<double>(sum.pixels_inside), setup);
    const double candidates = static_cast<double>(sum.candidates);
    fmt::print(
        "pixels settled (% of candidates): guesses {:.2f} (missed {:.3f}), Jacobian steps {:.3f}, slow path {:.3f}\n",
        100.0 * static_cast<double>(sum.guesses - sum.guess_misses) / candidates,
        100.0 * static_cast<double>(sum.guess_misses) / candidates,
        100.0 * static_cast<double>(sum.jacobian_steps) / candidates,
        100.0 * static_cast<double>(sum.slow_path_pixels) / candidates);
  }
  return 0;
}
