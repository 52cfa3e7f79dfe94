// `trivox slice SCENE -o DIR`: printer-ready slices of a scene (docs/CLI.md#slice).
#include <signal.h>
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

#include "cli_checks.h"
#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "trivox/material/material_function.h"
#include "trivox/output/layer_writer.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/job/job.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/job_lock.h"
#include "trivox/job/manifest.h"
#include "trivox/job/printed_extent.h"

namespace trivox::cli {

namespace {

struct SliceOptions {
  JobOptions job;
  bool quiet = false;
  bool resume = false;
  bool no_cache = false;
  double manifest_interval_s = JobParams{}.manifest_interval_seconds;
};

// Set by SIGINT / SIGTERM; the job stops starting layers once it is set. The handler is
// reset after the first signal, so a second Ctrl-C ends the program at once (the job can
// still be resumed: files are atomic and the manifest lags by at most a second).
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void on_stop_signal(int) { g_stop.store(true); }

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

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

// Bytes of the files a resumed job already has (they need no new space); 0 without a manifest.
std::uint64_t bytes_already_written(const JobParams& job) {
  const auto path = job.output_dir / manifest_file_name(job.shard_index, job.shard_count);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return 0;
  std::uint64_t bytes = 0;
  for (const ManifestFile& f : read_manifest(path).files) bytes += f.bytes;
  return bytes;
}

// The output folder, locked for this job (job_lock.h) before the scene is read, so that a
// second job into the same folder is refused at once.
//
// A job that fails for a reason a resume cannot mend (a scene that does not read, a setting
// the job cannot take) must not leave a half-written stack that looks like a result. The
// folder is put back as it was found when it was absent or empty; a folder that already held
// files is left alone, since they are not this job's to delete. Write errors and a fraction
// sum that breaks the rule keep the completed layers: the manifest then says the job failed,
// and --resume finishes it once there is room, or after a correction of the scene that
// cannot change them. The files are removed while the lock is still held, so that they
// cannot be another job's.
class LockedOutputFolder {
 public:
  LockedOutputFolder(std::filesystem::path dir, int shard_index, int shard_count) : dir_(std::move(dir)) {
    std::error_code ec;
    existed_ = std::filesystem::exists(dir_, ec);
    was_empty_ = existed_ && std::filesystem::is_directory(dir_, ec) && std::filesystem::is_empty(dir_, ec);
    try {
      lock_.emplace(dir_, shard_index, shard_count);
    } catch (const IoError&) {
      // A folder that cannot be created holds no other job: the checks that follow report it
      // (the disk check names the space there), or the job itself, which locks it then.
    }
  }
  LockedOutputFolder(const LockedOutputFolder&) = delete;
  LockedOutputFolder& operator=(const LockedOutputFolder&) = delete;
  ~LockedOutputFolder() {
    const bool roll_back = !committed_ && (!existed_ || was_empty_);
    std::error_code ec;
    // The lock files stay until the lock is released; the construction cache is this job's.
    if (roll_back)
      for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
        const std::string name = entry.path().filename().string();
        if (!name.starts_with(".trivox") || name == kConstructionCacheFolder)
          std::filesystem::remove_all(entry.path(), ec);
      }
    lock_.reset();                                                  // removes the lock files
    if (roll_back && !existed_) std::filesystem::remove(dir_, ec);  // only when nothing else came in
  }
  // The lock, or nullptr when the folder could not be created.
  JobFolderLock* lock() { return lock_ ? &*lock_ : nullptr; }
  void commit() noexcept { committed_ = true; }

 private:
  std::filesystem::path dir_;
  bool existed_ = false, was_empty_ = false, committed_ = false;
  std::optional<JobFolderLock> lock_;
};

void run(const SliceOptions& so) {
  // First, so that a Ctrl-C while the scene is read or the job estimated still ends with an
  // interrupted manifest rather than the default action.
  install_stop_handlers();
  const JobOptions& o = so.job;
  JobParams job = job_params_of(o);
  job.resume = so.resume;
  job.stop = &g_stop;
  job.manifest_interval_seconds = so.manifest_interval_s;
  // One job per folder: refused here, before the scene is read, when another job holds it.
  LockedOutputFolder folder(job.output_dir, job.shard_index, job.shard_count);
  job.folder_lock = folder.lock();
  if (job.folder_lock && job.folder_lock->taken_over_from() && !so.quiet)
    fmt::print(stderr, "trivox: note: took over the lock of a job that ended without releasing it ({})\n",
               *job.folder_lock->taken_over_from());

  // Constructed volumes come from the output folder's cache when an earlier run (or another
  // shard) built them (docs/SLICING.md, "The construction cache").
  std::optional<ConstructionCache> cache;
  if (!so.no_cache) cache.emplace(construction_cache_dir(job.output_dir));
  SceneReadOptions read;
  read.stop = &g_stop;
  read.construction_cache = cache ? &*cache : nullptr;
  const Scene scene = read_scene(o.scene, read);
  if (cache) {
    for (const std::string& w : cache->warnings()) fmt::print(stderr, "trivox: warning: {}\n", w);
    if (cache->hits() > 0 && !so.quiet)
      fmt::print(stderr, "trivox: {} constructed volume{} taken from the construction cache {}\n", cache->hits(),
                 cache->hits() == 1 ? "" : "s", cache->dir().string());
  }
  warn_about_printer(scene);
  SliceParams params = slice_params_of(o, scene);
  params.stop = &g_stop;  // Ctrl-C also ends the set-up (meshes) and a layer in progress
  const Slicer slicer(scene, params);
  const SliceLayout& L = slicer.layout();
  check_bitmap_shows_object(o, slicer);
  if (!o.no_checks) {
    // One sample layer is enough to refuse a job that is far too big; `trivox validate`
    // samples more for a closer estimate.
    JobEstimate estimate = estimate_job(slicer, job, EstimateParams{1, memory_limit_of(o).value_or(0)});
    if (so.resume) estimate.output_bytes -= std::min(estimate.output_bytes, bytes_already_written(job));
    check_job_fits(estimate, job, memory_limit_of(o));
  }
  if (!so.quiet)
    fmt::print(stderr,
               "trivox: {} cells, {} materials, printer {}: {} layers of {} x {} px ({:.4f} x {:.4f} mm pixels, {:.4f} "
               "mm layers)\n",
               scene.cells.size(), scene.num_materials(), scene.printer.name, L.num_layers, L.width_px, L.height_px,
               L.pitch_x_mm, L.pitch_y_mm, L.layer_mm);
  if (!so.quiet) {
    const DitherParams& d = slicer.dither_params();
    fmt::print(stderr, "trivox: dithering {}{}, {}, skin {} voxels\n", dither_method_name(d),
               d.method == DitherMethod::kErrorDiffusion ? (d.serpentine ? " (serpentine)" : " (raster order)") : "",
               d.vary_by_layer ? "varied by layer" : "the same in every layer", d.skin_voxels);
  }
  // Warnings go to standard error even with -q: they are about the result, not progress.
  for (const std::string& w : colour_warnings(scene, job_background(scene, job)))
    fmt::print(stderr, "trivox: warning: {}\n", w);
  TerminalProgress progress(so.quiet);
  // A job that fails on its input part way leaves no partial stack behind; one that fails
  // to write (a full disk) or is stopped keeps what it completed for --resume.
  JobStats st;
  try {
    st = run_slice_job(slicer, job, &progress);
  } catch (const IoError&) {
    folder.commit();
    throw;
  } catch (const FractionError& e) {
    folder.commit();
    std::fflush(stdout);
    fmt::print(stderr,
               "trivox: the job stopped at once; {} is marked failed and keeps the layers that were complete; correct "
               "the scene and run the same command with --resume: it keeps them if the correction cannot change them "
               "(and says why not otherwise)\n",
               (std::filesystem::path(o.output) / manifest_file_name(job.shard_index, job.shard_count)).string());
    throw;
  }
  folder.commit();
  const std::string manifest =
      (std::filesystem::path(o.output) / manifest_file_name(job.shard_index, job.shard_count)).string();
  if (st.interrupted)
    throw InterruptedError(
        fmt::format("stopped after {} layers; {} is marked interrupted; continue with the same command and --resume",
                    st.layers.size(), manifest));

  LayerStats total;
  for (const LayerStats& s : st.layers) total += s;
  const std::int64_t inside = total.pixels_inside, global = total.global_calls;
  fmt::print("sliced {} layers ({} x {} px) into {} in {:.2f} s with {}\n", st.layers.size(), L.width_px, L.height_px,
             o.output, st.seconds, thread_text(st.threads));
  fmt::print("voxels inside: {}, global solves: {} ({:.4f}% of inside voxels)\n", inside, global,
             inside > 0 ? 100.0 * static_cast<double>(global) / static_cast<double>(inside) : 0.0);
  if (!st.printed.empty()) {
    // Whole voxels, so each size is a multiple of the pitch: what the printer builds.
    const Vec3 printed = printed_box_mm(st.printed, L).size(), model = scene.bounds().size();
    fmt::print(
        "printed extent: {:.2f} x {:.2f} x {:.2f} mm ({} x {} px, {} layers{}); model: {:.2f} x {:.2f} x {:.2f} mm\n",
        printed.x, printed.y, printed.z, st.printed.col_hi - st.printed.col_lo + 1,
        st.printed.row_hi - st.printed.row_lo + 1, st.printed.layer_hi - st.printed.layer_lo + 1,
        st.layers_kept > 0 ? ", of the layers this run sliced" : "", model.x, model.y, model.z);
  }
  if (st.layers_kept > 0) fmt::print("resumed: {} layers were already complete\n", st.layers_kept);
  if (job.shard_count > 1)
    fmt::print("shard {} of {}: when every shard is complete, run `trivox merge {}`\n", job.shard_index,
               job.shard_count, o.output);
  if (st.padded_layers > 0)
    fmt::print("padded with {} empty layers to reach the {} layers Voxel Print needs\n", st.padded_layers,
               job.min_layers);
  // A stack shorter than GrabCAD Voxel Print takes is only written when asked for; say so.
  const int model_layers =
      (job.last_layer < 0 ? L.num_layers - 1 : std::min(job.last_layer, L.num_layers - 1)) - job.first_layer + 1;
  const int stack_layers = model_layers + st.padded_layers;
  const bool voxel_print = std::any_of(job.formats.begin(), job.formats.end(),
                                       [](const auto& f) { return f == "voxelprint" || f == "gcvf"; });
  if (voxel_print && stack_layers < JobParams::kVoxelPrintMinLayers)
    fmt::print(
        "note: the stack has {} layers, fewer than the {} GrabCAD Voxel Print needs, as --min-layers {} asked "
        "(manifest.json records min_layers {})\n",
        stack_layers, JobParams::kVoxelPrintMinLayers, job.min_layers, job.min_layers);
  // No voxel of the object in a job that sliced every model layer in this run (a resumed
  // job's kept layers, or another shard's, are not counted here): the object is lost.
  const int sliced_model_layers = static_cast<int>(st.layers.size());  // padding layers have no stats
  const bool empty = inside == 0 && job.shard_count == 1 && st.layers_kept == 0 && sliced_model_layers > 0;
  if (empty && o.allow_empty) fmt::print("note: the stack holds no voxel of the object (--allow-empty)\n");
  fmt::print("statistics: {}\n",
             (std::filesystem::path(o.output) /
              (job.shard_count > 1 ? fmt::format("stats.shard-{}-of-{}.json", job.shard_index, job.shard_count)
                                   : std::string("stats.json")))
                 .string());
  fmt::print("manifest: {}\n", manifest);
  if (empty && !o.allow_empty)
    throw EmptyResultError(fmt::format(
        "{}: the stack holds no voxel of the object: no pixel centre of its {} layers lies inside a cell (the "
        "object is thinner than a pixel, or falls between pixel centres); the files are written and {} is complete "
        "(--allow-empty accepts an empty stack)",
        o.output, sliced_model_layers, manifest));
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
