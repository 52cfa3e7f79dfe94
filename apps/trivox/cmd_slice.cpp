// `trivox slice SCENE -o DIR`: printer-ready slices of a scene (docs/CLI.md#slice).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_checks.h"
#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "stop_signal.h"
#include "trivox/job/job.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/printed_extent.h"
#include "trivox/job/slice_job.h"
#include "trivox/material/material_function.h"
#include "trivox/output/layer_writer.h"
#include "trivox/scene/scene.h"

namespace trivox::cli {

namespace {

struct SliceOptions {
  JobOptions job;
  bool quiet = false;
  bool resume = false;
  bool no_cache = false;
  double manifest_interval_s = JobParams{}.manifest_interval_seconds;
};

// A progress bar with an ETA on a terminal; a line every 10% otherwise (logs, pipes).
class TerminalProgress final : public ProgressSink {
 public:
  explicit TerminalProgress(bool quiet) : quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}
  void on_layer_done(int done, int total) override {
    if (quiet_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
    const int percent = 100 * done / total;
    if (tty_) {
      const int width = 30, filled = width * done / total;
      fmt::print(stderr, "\r[{:<{}}] {:3d}% layer {}/{}  elapsed {:.0f}s  ETA {:.0f}s ",
                 std::string(static_cast<std::size_t>(filled), '#'), width, percent, done, total, elapsed, eta);
      if (done == total) fmt::print(stderr, "\n");
    } else if (percent / 10 != last_decile_ || done == total) {
      last_decile_ = percent / 10;
      fmt::print(stderr, "trivox: sliced {}/{} layers ({}%), elapsed {:.1f}s, ETA {:.1f}s\n", done, total, percent,
                 elapsed, eta);
    }
  }

 private:
  bool quiet_, tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The summary after a job: what it sliced, the counts, the printed extent, and notes on a
// resumed, sharded, padded or short stack.
void print_summary(const JobOptions& o, const SliceJob& slice_job, const Slicer& slicer, const JobStats& st) {
  const SliceLayout& L = slicer.layout();
  const JobParams& job = slice_job.params().job;
  const std::int64_t inside = st.total.pixels_inside, global = st.total.global_calls;
  // The model's layers this job covers, numbered from 1 as --layers numbers them, when the
  // job is not the whole model (the layer files number the stack from 1: CLI.md).
  std::string range;
  if (st.first_layer == st.last_layer)
    range = fmt::format(", layer {} of the model's {}", st.last_layer + 1, L.num_layers);
  else if (st.first_layer > 0 || st.last_layer < L.num_layers - 1)
    range = fmt::format(", layers {} to {} of the model's {}", st.first_layer + 1, st.last_layer + 1, L.num_layers);
  fmt::print("sliced {} layer{} ({} x {} px{}) into {} in {:.2f} s with {}\n", st.layers.size(),
             st.layers.size() == 1 ? "" : "s", L.width_px, L.height_px, range, o.output, st.seconds,
             thread_text(st.threads));
  fmt::print("voxels inside: {}, global solves: {} ({:.4f}% of inside voxels)\n", inside, global,
             global_share_percent(st.total));
  if (!st.printed.empty()) {
    // Whole voxels, so each size is a multiple of the pitch: what the printer builds.
    const Vec3 printed = printed_box_mm(st.printed, L).size(), model = slicer.object_bounds().size();
    const int printed_layers = st.printed.layer_hi - st.printed.layer_lo + 1;
    fmt::print(
        "printed extent: {:.2f} x {:.2f} x {:.2f} mm ({} x {} px, {} layer{}); model: {:.2f} x {:.2f} x {:.2f} mm\n",
        printed.x, printed.y, printed.z, st.printed.col_hi - st.printed.col_lo + 1,
        st.printed.row_hi - st.printed.row_lo + 1, printed_layers, printed_layers == 1 ? "" : "s", model.x, model.y,
        model.z);
  }
  if (st.layers_kept > 0)
    fmt::print("resumed: {} layer{} already complete\n", st.layers_kept, st.layers_kept == 1 ? " was" : "s were");
  if (job.shard_count > 1)
    fmt::print("shard {} of {}: when every shard is complete, run `trivox merge {}`\n", job.shard_index,
               job.shard_count, o.output);
  if (st.padded_layers > 0)
    fmt::print("padded with {} empty layers to reach {} layers{}\n", st.padded_layers, min_layers_of(job),
               job.min_layers ? "" : ", as Voxel Print needs");
  // A stack shorter than GrabCAD Voxel Print takes is only written when asked for; say so.
  const int model_layers = st.last_layer - st.first_layer + 1;
  const int stack_layers = model_layers + st.padded_layers;
  const bool voxel_print = std::any_of(job.formats.begin(), job.formats.end(),
                                       [](const std::string& f) { return layer_writer_feeds_voxel_print(f); });
  if (voxel_print && stack_layers < JobParams::kVoxelPrintMinLayers)
    fmt::print(
        "note: the stack has {} layers, fewer than the {} GrabCAD Voxel Print needs, as --min-layers {} asked "
        "(manifest.json records min_layers {})\n",
        stack_layers, JobParams::kVoxelPrintMinLayers, min_layers_of(job), min_layers_of(job));
  if (slice_job.empty_result(st) && o.allow_empty)
    fmt::print("note: the stack holds no voxel of the object (--allow-empty)\n");
  fmt::print("statistics: {}\n", slice_job.stats_path().string());
  fmt::print("manifest: {}\n", slice_job.manifest_path().string());
}

// The scene as read through the job, and what the construction cache said about it.
Scene read_scene_of(const SliceOptions& so, SliceJob& slice_job) {
  Scene scene = slice_job.read_scene(so.job.scene);
  if (so.no_cache) return scene;
  for (const std::string& w : slice_job.cache_warnings()) fmt::print(stderr, "trivox: warning: {}\n", w);
  const int hits = slice_job.cache_hits();
  if (hits > 0 && !so.quiet)
    fmt::print(stderr, "trivox: {} constructed volume{} taken from the construction cache {}\n", hits,
               hits == 1 ? "" : "s", slice_job.cache_dir().string());
  return scene;
}

void print_job_lines(const SliceOptions& so, const Scene& scene, const Slicer& slicer) {
  if (so.quiet) return;
  const SliceLayout& L = slicer.layout();
  fmt::print(stderr,
             "trivox: {} cells, {} materials, printer {}: {} layers of {} x {} px ({:.4f} x {:.4f} mm pixels, {:.4f} "
             "mm layers)\n",
             scene.cells.size(), scene.num_materials(), scene.printer.name, L.num_layers, L.width_px, L.height_px,
             L.pitch_x_mm, L.pitch_y_mm, L.layer_mm);
  // A greyscale job exposes grey levels: say how; the dithering concerns only the formats that
  // show materials (the previews, Voxel Print), when there are any.
  std::vector<std::string> dithered;
  for (const std::string& f : so.job.formats)
    if (!layer_writer_writes_greys(f)) dithered.push_back(f);
  if (scene.greyscale) {
    const GreyscaleDef& g = *scene.greyscale;
    fmt::print(stderr, "trivox: greyscale: {}, edges anti-aliased {} x {} sub-samples\n",
               g.material >= 0
                   ? fmt::format("the fraction of {}", scene.materials[static_cast<std::size_t>(g.material)].name)
                   : std::string("each cell's greyscale source"),
               g.antialiasing, g.antialiasing);
    if (dithered.empty()) return;
  }
  const DitherParams& d = slicer.dither_params();
  fmt::print(stderr, "trivox: dithering {}{}, {}, skin {} voxels{}\n", dither_method_name(d),
             d.method == DitherMethod::kErrorDiffusion ? (d.serpentine ? " (serpentine)" : " (raster order)") : "",
             d.vary_by_layer ? "varied by layer" : "the same in every layer", d.skin_voxels,
             scene.greyscale ? fmt::format(", for {}", fmt::join(dithered, ", ")) : std::string());
}

void run(const SliceOptions& so) {
  // First, so that a Ctrl-C while the scene is read or the job estimated still ends cleanly
  // (stop_signal.h); a second one ends the program at once, and the job can still be resumed:
  // files are atomic and the manifest lags by at most a second.
  const std::atomic<bool>* stop = stop_on_signals();
  const JobOptions& o = so.job;
  SliceJobParams sp;
  sp.job = job_params_of(o);
  sp.job.resume = so.resume;
  sp.job.stop = stop;
  sp.job.manifest_interval_seconds = so.manifest_interval_s;
  sp.construction_cache = !so.no_cache;
  sp.checks = !o.no_checks;
  sp.allow_empty = o.allow_empty;
  // One job per folder: refused here, before the scene is read, when another job holds it.
  // A job that fails on its input leaves the folder as it found it (slice_job.h).
  SliceJob slice_job(std::move(sp));
  const JobParams& job = slice_job.params().job;
  if (const auto holder = slice_job.lock_taken_over_from(); holder && !so.quiet)
    fmt::print(stderr, "trivox: note: took over the lock of a job that ended without releasing it ({})\n", *holder);
  if (slice_job.locked_by_files() && !so.quiet)
    fmt::print(stderr,
               "trivox: note: {} is locked by its lock files alone: its file system has no flock locks, or "
               "TRIVOX_LOCKS=files (docs/CLUSTER.md, \"Locks\")\n",
               job.output_dir.string());

  const Scene scene = read_scene_of(so, slice_job);
  warn_about_printer(scene);
  const Slicer slicer(scene, slice_job.slice_params(slice_params_of(o, scene)));
  check_bitmap_shows_object(slicer, o.scene, o.allow_empty);
  slice_job.check_fits(slicer);
  print_job_lines(so, scene, slicer);
  // Warnings go to standard error even with -q: they are about the result, not progress.
  for (const std::string& w : colour_warnings(scene, job_preview_background(scene, job)))
    fmt::print(stderr, "trivox: warning: {}\n", w);
  TerminalProgress progress(so.quiet);
  JobStats st;
  try {
    st = slice_job.run(slicer, &progress);
  } catch (const FractionError& e) {
    std::fflush(stdout);
    fmt::print(stderr,
               "trivox: the job stopped at once; {} is marked failed and keeps the layers that were complete; correct "
               "the scene and run the same command with --resume: it keeps them if the correction cannot change them "
               "(and says why not otherwise)\n",
               slice_job.manifest_path().string());
    throw;
  }
  if (st.interrupted) {
    std::string message =
        fmt::format("stopped after {} layers; {} is marked interrupted; continue with the same command and --resume",
                    st.layers.size(), slice_job.manifest_path().string());
    if (const std::string note = stack_resume_note(slice_job.params().job); !note.empty()) message += " (" + note + ")";
    throw InterruptedError(message);
  }
  print_summary(o, slice_job, slicer, st);
  slice_job.check_result(st);
}

}  // namespace

void add_slice_command(CLI::App& app) {
  auto opts = std::make_shared<SliceOptions>();
  CLI::App* cmd = app.add_subcommand("slice", "Slice a scene into printer-ready layer images");
  add_job_options(*cmd, opts->job, true);
  cmd->add_flag("-q,--quiet", opts->quiet, "No progress output");
  cmd->add_flag(
      "--resume", opts->resume,
      "Continue the job recorded in the folder's manifest; refused when the scene, models or settings differ");
  cmd->add_flag("--no-cache", opts->no_cache,
                "Build every constructed volume, neither reading nor writing the construction cache in the output "
                "folder (.trivox-cache)");
  cmd->add_option("--manifest-interval", opts->manifest_interval_s,
                  "Seconds between rewrites of manifest.json while layers complete (0: after every layer); a "
                  "killed job redoes at most the layers of one interval")
      ->check(number_in(0.0, 86400.0));
  cmd->callback([opts] { run(*opts); });
}

}  // namespace trivox::cli
