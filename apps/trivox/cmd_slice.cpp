// `trivox slice SCENE -o DIR`: printer-ready slices of a scene (docs/CLI.md#slice).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.h"
#include "commands.h"
#include "trivox/output/layer_writer.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/job.h"

namespace trivox::cli {

namespace {

struct SliceOptions {
  std::string scene;
  std::string output;
  int threads = 0;
  std::string layers;
  std::string tracing = std::string(to_string(SliceParams{}.tracing));
  double residual_tolerance_mm = SliceParams{}.newton.residual_tolerance_model;
  std::vector<std::string> formats{"voxelprint"};
  std::string prefix = "slice_";
  std::vector<int> background{255, 255, 255, 255};
  int min_layers = 30;
  bool quiet = false;
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
      fmt::print(stderr, "\r[{:<{}}] {:3d}% layer {}/{}  elapsed {:.0f}s  ETA {:.0f}s ", std::string(static_cast<std::size_t>(filled), '#'),
                 width, percent, done, total, elapsed, eta);
      if (done == total) fmt::print(stderr, "\n");
    } else if (percent / 10 != last_decile_ || done == total) {
      last_decile_ = percent / 10;
      fmt::print(stderr, "trivox: sliced {}/{} layers ({}%), elapsed {:.1f}s, ETA {:.1f}s\n", done, total, percent, elapsed, eta);
    }
  }

 private:
  bool quiet_, tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// "a:b" (1-based, inclusive, as in the file names; either end may be left out).
void parse_layers(const std::string& text, JobParams& p) {
  if (text.empty()) return;
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw UsageError(fmt::format("--layers takes FIRST:LAST (1-based), got '{}'", text));
  try {
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    if (!a.empty()) p.first_layer = std::stoi(a) - 1;
    if (!b.empty()) p.last_layer = std::stoi(b) - 1;
  } catch (const std::exception&) {
    throw UsageError(fmt::format("--layers takes FIRST:LAST (1-based), got '{}'", text));
  }
  if (p.first_layer < 0 || (p.last_layer >= 0 && p.last_layer < p.first_layer))
    throw UsageError(fmt::format("--layers {}: layers count from 1 and FIRST must not exceed LAST", text));
}

// A job that fails (a fraction sum above 1 met in layer 200, a write error) must not leave a
// half-written stack that looks like a result. The folder is put back as it was found when
// it was absent or empty; a folder that already held files is left alone, since they are
// not this job's to delete.
class OutputRollback {
 public:
  explicit OutputRollback(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::error_code ec;
    existed_ = std::filesystem::exists(dir_, ec);
    was_empty_ = existed_ && std::filesystem::is_directory(dir_, ec) && std::filesystem::is_empty(dir_, ec);
  }
  OutputRollback(const OutputRollback&) = delete;
  OutputRollback& operator=(const OutputRollback&) = delete;
  ~OutputRollback() {
    if (committed_ || (existed_ && !was_empty_)) return;
    std::error_code ec;
    if (!existed_) {
      std::filesystem::remove_all(dir_, ec);
      return;
    }
    for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) std::filesystem::remove_all(entry.path(), ec);
  }
  void commit() noexcept { committed_ = true; }

 private:
  std::filesystem::path dir_;
  bool existed_ = false, was_empty_ = false, committed_ = false;
};

void run(const SliceOptions& o) {
  SliceParams params;
  const auto strategy = parse_tracing_strategy(o.tracing);
  if (!strategy) throw UsageError(fmt::format("--tracing must be none, previous-point, previous-line, full, predict or flood, got '{}'", o.tracing));
  params.tracing = *strategy;
  params.newton.residual_tolerance_model = o.residual_tolerance_mm;
  JobParams job;
  job.output_dir = o.output;
  job.threads = o.threads;
  job.formats = o.formats;
  job.prefix = o.prefix;
  job.min_layers = o.min_layers;
  if (o.background.size() != 4) throw UsageError("--background takes four numbers R,G,B,A");
  for (std::size_t i = 0; i < 4; ++i) {
    if (o.background[i] < 0 || o.background[i] > 255) throw UsageError("--background values are 0..255");
    job.background_rgba[i] = static_cast<std::uint8_t>(o.background[i]);
  }
  parse_layers(o.layers, job);

  const Scene scene = read_scene(o.scene);
  const Slicer slicer(scene, params);
  const SliceLayout& L = slicer.layout();
  if (!o.quiet)
    fmt::print(stderr, "trivox: {} cells, {} materials, printer {}: {} layers of {} x {} px ({:.4f} x {:.4f} mm pixels, {:.4f} mm layers)\n",
               scene.cells.size(), scene.num_materials(), scene.printer.name, L.num_layers, L.width_px, L.height_px,
               L.pitch_x_mm, L.pitch_y_mm, L.layer_mm);
  TerminalProgress progress(o.quiet);
  OutputRollback rollback(job.output_dir);
  const JobStats st = run_slice_job(slicer, job, &progress);
  rollback.commit();

  std::int64_t inside = 0, global = 0;
  for (const LayerStats& s : st.layers) {
    inside += s.pixels_inside;
    global += s.global_calls;
  }
  fmt::print("sliced {} layers ({} x {} px) into {} in {:.2f} s with {} threads\n", st.layers.size(), L.width_px,
             L.height_px, o.output, st.seconds, st.threads);
  fmt::print("voxels inside: {}, global solves: {} ({:.4f}% of inside voxels)\n", inside, global,
             inside > 0 ? 100.0 * static_cast<double>(global) / static_cast<double>(inside) : 0.0);
  if (st.padded_layers > 0)
    fmt::print("padded with {} empty layers to reach the {} layers Voxel Print needs\n", st.padded_layers, job.min_layers);
  fmt::print("statistics: {}\n", (std::filesystem::path(o.output) / "stats.json").string());
}

}  // namespace

void add_slice_command(CLI::App& app) {
  auto opts = std::make_shared<SliceOptions>();
  CLI::App* cmd = app.add_subcommand("slice", "Slice a scene into printer-ready layer images");
  cmd->add_option("scene", opts->scene, "Scene file (JSON, docs/SCENE.md)")->required();
  cmd->add_option("-o,--output", opts->output, "Output folder (created if missing)")->required();
  cmd->add_option("-j,--threads", opts->threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--layers", opts->layers, "Only layers FIRST:LAST (1-based, inclusive)");
  cmd->add_option("--tracing", opts->tracing, "Seeding of the inverse: none, previous-point, previous-line, full (the paper's), predict, flood")
      ->capture_default_str();
  cmd->add_option("--residual-tolerance", opts->residual_tolerance_mm,
                  "Largest |V(u,v,w) - pixel centre| of an inside pixel's solution, mm")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--format", opts->formats, "Outputs: voxelprint (RGBA PNG stack), bitmaps (1-bit PNG per material)")
      ->delimiter(',')
      ->check(CLI::IsMember(layer_writer_names()))
      ->capture_default_str();
  cmd->add_option("--prefix", opts->prefix, "File-name prefix of the layer images")->capture_default_str();
  cmd->add_option("--background", opts->background, "Background colour R,G,B,A")->delimiter(',')->capture_default_str();
  cmd->add_option("--min-layers", opts->min_layers, "Pad with empty layers up to this count")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opts->quiet, "No progress output");
  cmd->callback([opts] { run(*opts); });
}

}  // namespace trivox::cli
