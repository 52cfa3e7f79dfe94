// Slicing (slice/): one layer to numpy arrays, and the whole job of `trivox slice` with its
// progress, Ctrl-C and resume (docs/PYTHON.md, "Slicing").
//
// The job runs on a thread of its own (its layers on the job's workers) while the calling thread,
// which owns the GIL, waits for progress with the GIL released: every tenth of a second, and
// after every layer, it takes the GIL back to call the progress callable and to run
// PyErr_CheckSignals, Python's own check for Ctrl-C. A pending KeyboardInterrupt (or an
// exception of the progress callable) raises the job's stop flag (JobParams::stop): no new
// layer starts, the layers in progress finish, the manifest is marked interrupted, and the
// exception is raised once the job has returned, so the folder can be resumed.
#include <Python.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/output/layer_writer.h"
#include "trivox/slice/job.h"
#include "trivox/slice/job_estimate.h"
#include "trivox/slice/manifest.h"
#include "trivox/slice/slicer.h"

namespace trivox::python {

namespace {

// The library's slicer and the scene it keeps a reference to.
struct PySlicer {
  ScenePtr scene;
  std::unique_ptr<Slicer> slicer;
};

// A zero-copy array over a value moved to the heap, freed with the array.
template <class T, class Owner, class DataOf>
py::array_t<T> owned_array(Owner&& value, DataOf data_of, std::vector<py::ssize_t> shape) {
  auto* held = new Owner(std::move(value));
  py::capsule owner(held, [](void* p) { delete static_cast<Owner*>(p); });
  return py::array_t<T>(shape, data_of(*held), owner);
}

py::dict stats_dict(const LayerStats& s) {
  py::dict d;
  d["layer"] = s.layer;
  d["z_mm"] = s.z_mm;
  d["seconds"] = s.seconds;
  d["seconds_inverse"] = s.seconds_inverse;
  d["seconds_material"] = s.seconds_material;
  d["seconds_dither"] = s.seconds_dither;
  d["pixels_total"] = s.pixels_total;
  d["pixels_inside"] = s.pixels_inside;
  d["candidates"] = s.candidates;
  d["global_calls"] = s.global_calls;
  d["global_unseeded"] = s.global_unseeded;
  d["newton_evals"] = s.newton_evals;
  d["guesses"] = s.guesses;
  d["guess_misses"] = s.guess_misses;
  d["jacobian_steps"] = s.jacobian_steps;
  d["slow_path_pixels"] = s.slow_path_pixels;
  d["folded_pixels"] = s.folded_pixels;
  d["unresolved_pixels"] = s.unresolved_pixels;
  d["voxels_per_material"] = s.voxels_per_material;
  d["pixels_per_cell"] = s.pixels_per_cell;
  return d;
}

std::unique_ptr<PySlicer> make_slicer(const SceneHandle& handle, const std::string& tracing,
                                      double residual_tolerance_mm, std::optional<double> outline_tolerance_mm,
                                      const std::optional<std::string>& dither, std::optional<int> skin,
                                      std::optional<bool> vary_by_layer) {
  // The settings of `trivox slice` (apps/trivox/job_options.cpp): the scene's dithering with
  // the options given here on top.
  SliceParams params;
  const auto strategy = parse_tracing_strategy(tracing);
  if (!strategy)
    throw py::value_error("tracing must be none, previous-point, previous-line, full, predict or flood, got '" +
                          tracing + "'");
  params.tracing = *strategy;
  params.newton.residual_tolerance_model = residual_tolerance_mm;
  params.outline_tolerance_mm = outline_tolerance_mm;
  DitherParams d = handle.scene->dithering.value_or(DitherParams{});
  if (dither && !set_dither_method(*dither, d)) {
    std::string names;
    for (std::string_view n : dither_method_names()) names += (names.empty() ? "" : ", ") + std::string(n);
    throw py::value_error("dither must be one of " + names + ", got '" + *dither + "'");
  }
  if (skin) d.skin_voxels = *skin;
  if (vary_by_layer) d.vary_by_layer = *vary_by_layer;
  params.dither = d;
  auto s = std::make_unique<PySlicer>();
  s->scene = handle.scene;
  {
    py::gil_scoped_release release;
    s->slicer = std::make_unique<Slicer>(*s->scene, params);
  }
  return s;
}

py::dict slice_one(const PySlicer& s, int layer, bool fractions, bool owner) {
  const SliceLayout& L = s.slicer->layout();
  if (layer < 0 || layer >= L.num_layers)
    throw py::index_error("layer " + std::to_string(layer) + " is out of range: the scene has " +
                          std::to_string(L.num_layers) + " layers (0 to " + std::to_string(L.num_layers - 1) + ")");
  LayerResult r;
  {
    py::gil_scoped_release release;
    r = s.slicer->slice_layer(layer, {.owner = owner, .rasters = fractions});
  }
  const py::ssize_t h = L.height_px, w = L.width_px;
  py::dict out;
  auto values_of = [](const auto& raster) { return raster.values().data(); };
  out["labels"] = owned_array<std::uint8_t>(std::move(r.labels), values_of, {h, w});
  out["stats"] = stats_dict(r.stats);
  if (fractions) {
    const py::ssize_t m = r.rasters.fractions.num_materials();
    out["fractions"] = owned_array<float>(std::move(r.rasters.fractions), values_of, {h, w, m});
    out["inside"] = owned_array<std::uint8_t>(std::move(r.rasters.inside), values_of, {h, w});
  }
  if (owner) {
    out["owner"] = owned_array<int>(std::move(r.owner), [](const std::vector<int>& v) { return v.data(); }, {h, w});
  }
  return out;
}

// Progress events from the job's workers, handed to the waiting Python thread.
class QueuedProgress final : public ProgressSink {
 public:
  void on_layer_done(int done, int total) override {
    const std::lock_guard lock(mutex_);
    events_.emplace_back(done, total);
    changed_.notify_all();
  }
  void finish() {
    const std::lock_guard lock(mutex_);
    finished_ = true;
    changed_.notify_all();
  }
  // Waits up to `timeout` for an event or the end; returns the events so far.
  std::deque<std::pair<int, int>> wait(std::chrono::milliseconds timeout, bool& finished) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return finished_ || !events_.empty(); });
    finished = finished_;
    return std::exchange(events_, {});
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<int, int>> events_;
  bool finished_ = false;
};

// Bytes of the files a resumed job already has (they need no new space), as `trivox slice`.
std::uint64_t bytes_already_written(const JobParams& job) {
  const auto path = job.output_dir / manifest_file_name(job.shard_index, job.shard_count);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return 0;
  std::uint64_t bytes = 0;
  for (const ManifestFile& f : read_manifest(path).files) bytes += f.bytes;
  return bytes;
}

py::dict run_job(const PySlicer& s, const std::filesystem::path& output_dir, const std::vector<std::string>& formats,
                 int first_layer, int last_layer, int threads, const std::string& prefix,
                 const std::optional<std::vector<int>>& background, int min_layers,
                 const std::vector<int>& preview_layers, int shard_index, int shard_count, bool resume,
                 const py::object& progress, bool checks, std::optional<double> memory_limit_mb,
                 double manifest_interval_seconds) {
  JobParams job;
  job.output_dir = output_dir;
  job.first_layer = first_layer;
  job.last_layer = last_layer;
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: every core)");
  job.threads = threads;
  job.formats = formats;
  job.prefix = prefix;
  // None: the job's automatic background (job_background(): the public writers' black, or
  // another unused colour when a material is black), as the program's default.
  if (background) {
    if (background->size() != 3 && background->size() != 4)
      throw py::value_error("background takes three numbers R, G, B (or R, G, B, 255)");
    std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
    for (std::size_t i = 0; i < background->size(); ++i) {
      if ((*background)[i] < 0 || (*background)[i] > 255) throw py::value_error("background values are 0..255");
      rgba[i] = static_cast<std::uint8_t>((*background)[i]);
    }
    if (rgba[3] != 255) throw py::value_error("printer images are opaque: the background's alpha must be 255");
    job.background_rgba = rgba;
  }
  if (min_layers < 0) throw py::value_error("min_layers must be >= 0");
  job.min_layers = min_layers;
  job.preview_layers = preview_layers;
  job.shard_index = shard_index;
  job.shard_count = shard_count;
  job.resume = resume;
  if (!(manifest_interval_seconds >= 0.0)) throw py::value_error("manifest_interval_seconds must be >= 0");
  job.manifest_interval_seconds = manifest_interval_seconds;
  for (const std::string& f : formats) {
    const std::vector<std::string> names = layer_writer_names();
    if (std::find(names.begin(), names.end(), f) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw py::value_error("unknown format '" + f + "'; the formats are " + list);
    }
  }
  std::atomic<bool> stop{false};
  job.stop = &stop;
  if (checks) {
    // As `trivox slice`: one sample layer refuses a job far too big for the disk or memory.
    const std::optional<std::uint64_t> limit =
        memory_limit_mb ? std::optional<std::uint64_t>(static_cast<std::uint64_t>(*memory_limit_mb * 1e6))
                        : memory_limit_bytes();
    py::gil_scoped_release release;
    JobEstimate estimate = estimate_job(*s.slicer, job, EstimateParams{1, limit.value_or(0)});
    if (resume) estimate.output_bytes -= std::min(estimate.output_bytes, bytes_already_written(job));
    check_job_fits(estimate, job, limit);
  }

  QueuedProgress sink;
  JobStats stats;
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      stats = run_slice_job(*s.slicer, job, &sink);
    } catch (...) {
      failure = std::current_exception();
    }
    sink.finish();
  });
  std::optional<py::error_already_set> raised;
  for (bool finished = false; !finished;) {
    std::deque<std::pair<int, int>> events;
    {
      py::gil_scoped_release release;
      events = sink.wait(std::chrono::milliseconds(100), finished);
    }
    try {
      if (!raised && !progress.is_none())
        for (const auto& [done, total] : events) progress(done, total);
      if (!raised && PyErr_CheckSignals() != 0) throw py::error_already_set();
    } catch (py::error_already_set& e) {
      raised = std::move(e);
      stop = true;
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (failure) std::rethrow_exception(failure);
  if (raised) throw std::move(*raised);

  py::dict out;
  py::list layers;
  for (const LayerStats& l : stats.layers) layers.append(stats_dict(l));
  out["layers"] = layers;
  out["padded_layers"] = stats.padded_layers;
  out["seconds"] = stats.seconds;
  out["threads"] = stats.threads;
  out["files"] = stats.files;
  out["layers_kept"] = stats.layers_kept;
  out["interrupted"] = stats.interrupted;
  return out;
}

}  // namespace

void bind_slice(py::module_& m) {
  py::class_<SliceLayout>(m, "Layout",
                          "Where each layer and pixel of a job lies in model space (mm): pixel (col, row) samples "
                          "x = x0_mm + (col + 0.5) pitch_x_mm, y = y_top_mm - (row + 0.5) pitch_y_mm (row 0 on "
                          "top); layer l samples z = z0_mm + (l + 0.5) layer_mm.")
      .def_readonly("x0_mm", &SliceLayout::x0_mm, "The left edge of column 0 (mm).")
      .def_readonly("y_top_mm", &SliceLayout::y_top_mm, "The top edge of row 0 (mm).")
      .def_readonly("z0_mm", &SliceLayout::z0_mm, "The bottom of layer 0 (mm).")
      .def_readonly("pitch_x_mm", &SliceLayout::pitch_x_mm, "Pixel pitch along x, the image width (mm).")
      .def_readonly("pitch_y_mm", &SliceLayout::pitch_y_mm, "Pixel pitch along y, the image height (mm).")
      .def_readonly("layer_mm", &SliceLayout::layer_mm, "Layer thickness (mm).")
      .def_readonly("width_px", &SliceLayout::width_px, "Pixels per row (the images' width).")
      .def_readonly("height_px", &SliceLayout::height_px, "Rows (the images' height).")
      .def_readonly("num_layers", &SliceLayout::num_layers, "Layers of the model.")
      .def("x_of_col", &SliceLayout::x_of_col, py::arg("col"), "x (mm) of the centre of column col.")
      .def("y_of_row", &SliceLayout::y_of_row, py::arg("row"), "y (mm) of the centre of row row.")
      .def("z_of_layer", &SliceLayout::z_of_layer, py::arg("layer"), "z (mm) of the middle of layer layer.")
      .def("__repr__", [](const SliceLayout& L) {
        return "<trivox.Layout " + std::to_string(L.num_layers) + " layers of " + std::to_string(L.width_px) + " x " +
               std::to_string(L.height_px) + " px>";
      });

  py::class_<PySlicer>(m, "_Slicer")
      .def(py::init(&make_slicer), py::arg("scene"), py::arg("tracing"), py::arg("residual_tolerance_mm"),
           py::arg("outline_tolerance_mm"), py::arg("dither"), py::arg("skin"), py::arg("vary_by_layer"))
      .def_property_readonly("layout", [](const PySlicer& s) { return s.slicer->layout(); })
      .def_property_readonly(
          "background",
          [](const PySlicer& s) {
            const auto c = job_background(s.slicer->scene(), JobParams{});
            return py::make_tuple(c[0], c[1], c[2], c[3]);
          },
          "The job's automatic background colour (r, g, b, 255): black, or white or a grey when a material "
          "takes black (trivox::job_background).")
      .def_property_readonly("dithering",
                             [](const PySlicer& s) {
                               const DitherParams& d = s.slicer->dither_params();
                               py::dict out;
                               out["method"] = std::string(dither_method_name(d));
                               out["serpentine"] = d.serpentine;
                               out["vary_by_layer"] = d.vary_by_layer;
                               out["skin_voxels"] = d.skin_voxels;
                               return out;
                             })
      .def("slice_layer", &slice_one, py::arg("layer"), py::arg("fractions") = false, py::arg("owner") = false)
      .def("run_job", &run_job, py::arg("output_dir"), py::arg("formats"), py::arg("first_layer"),
           py::arg("last_layer"), py::arg("threads"), py::arg("prefix"), py::arg("background"), py::arg("min_layers"),
           py::arg("preview_layers"), py::arg("shard_index"), py::arg("shard_count"), py::arg("resume"),
           py::arg("progress"), py::arg("checks"), py::arg("memory_limit_mb"), py::arg("manifest_interval_seconds"));
}

}  // namespace trivox::python
