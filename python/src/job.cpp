// The whole job of `trivox slice` from Python (job/, docs/PYTHON.md, "Slicing"): trivox._Job
// is the library's SliceJob (job/slice_job.h), so a Python job locks its folder before the
// scene is read, reads the scene through the folder's construction cache, checks that it
// fits, puts the folder back as found when it fails on its input, and refuses a stack without
// the object (EmptyResultError) as the program does.
//
// The job runs on a thread of its own (its layers on the job's workers) while the calling thread,
// which owns the GIL, waits for progress with the GIL released: every tenth of a second, and
// after every layer, it takes the GIL back to call the progress callable and to run
// PyErr_CheckSignals, Python's own check for Ctrl-C. A pending KeyboardInterrupt (or an
// exception of the progress callable) raises the job's stop flag (JobParams::stop): no new
// layer starts, the layers in progress finish, the manifest is marked interrupted, and the
// exception is raised once the job has returned, so the folder can be resumed.
#include <Python.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/slice_job.h"
#include "trivox/limits.h"
#include "trivox/output/layer_writer.h"

namespace trivox::python {

namespace {

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

// The job and its stop flag, which the job's parameters point to (so it never moves).
struct PyJob {
  std::atomic<bool> stop{false};
  std::unique_ptr<SliceJob> job;

  SliceJob& open() const {
    if (!job) throw py::value_error("the job is closed");
    return *job;
  }
};

// The background of slice(): None (automatic, job_background()) or R, G, B[, 255].
std::optional<std::array<std::uint8_t, 4>> background_of(const std::optional<std::vector<int>>& background) {
  if (!background) return std::nullopt;
  if (background->size() != 3 && background->size() != 4)
    throw py::value_error("background takes three numbers R, G, B (or R, G, B, 255)");
  std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
  for (std::size_t i = 0; i < background->size(); ++i) {
    if ((*background)[i] < 0 || (*background)[i] > 255) throw py::value_error("background values are 0..255");
    rgba[i] = static_cast<std::uint8_t>((*background)[i]);
  }
  if (rgba[3] != 255) throw py::value_error("printer images are opaque: the background's alpha must be 255");
  return rgba;
}

void check_formats(const std::vector<std::string>& formats) {
  const std::vector<std::string> names = layer_writer_names();
  for (const std::string& f : formats) {
    if (std::find(names.begin(), names.end(), f) != names.end()) continue;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw py::value_error("unknown format '" + f + "'; the formats are " + list);
  }
}

// Checks the settings (ValueError) before anything is locked or written, then locks the folder.
std::unique_ptr<PyJob> make_job(const std::filesystem::path& output_dir, const std::vector<std::string>& formats,
                                int first_layer, int last_layer, int threads, const std::string& prefix,
                                const std::optional<std::vector<int>>& background, std::optional<int> min_layers,
                                const std::vector<int>& preview_layers, int shard_index, int shard_count, bool resume,
                                bool checks, std::optional<double> memory_limit_mb, double manifest_interval_seconds,
                                bool construction_cache, bool allow_empty) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: every core)");
  if (min_layers && *min_layers < 0) throw py::value_error("min_layers must be >= 0");
  if (!(manifest_interval_seconds >= 0.0)) throw py::value_error("manifest_interval_seconds must be >= 0");
  check_formats(formats);
  auto py_job = std::make_unique<PyJob>();
  SliceJobParams p;
  JobParams& job = p.job;
  job.output_dir = output_dir;
  job.first_layer = first_layer;
  job.last_layer = last_layer;
  job.threads = threads;
  job.formats = formats;
  job.prefix = prefix;
  job.background_rgba = background_of(background);
  job.min_layers = min_layers;
  job.preview_layers = preview_layers;
  job.shard_index = shard_index;
  job.shard_count = shard_count;
  job.resume = resume;
  job.manifest_interval_seconds = manifest_interval_seconds;
  job.stop = &py_job->stop;
  // As `trivox slice`: the machine's memory unless a limit is given; none without checks.
  if (checks) job.memory_limit_bytes = memory_limit_from_mb(memory_limit_mb.value_or(0.0));
  p.checks = checks;
  p.construction_cache = construction_cache;
  p.allow_empty = allow_empty;
  py_job->job = std::make_unique<SliceJob>(std::move(p));
  return py_job;
}

// Runs the job on a thread of its own while this one serves progress and Ctrl-C (above).
JobStats run_with_progress(PyJob& py_job, const PySlicer& py_slicer, const py::object& progress) {
  const Slicer& slicer = *py_slicer.slicer;
  py_slicer.stop = false;
  SliceJob& job = py_job.open();
  QueuedProgress sink;
  JobStats stats;
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      stats = job.run(slicer, &sink);
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
      py_job.stop = true;
      py_slicer.stop = true;  // the layers in progress end within a row
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (failure) std::rethrow_exception(failure);
  if (raised) throw std::move(*raised);
  return stats;
}

py::dict run_job(PyJob& py_job, const PySlicer& s, const py::object& progress) {
  SliceJob& job = py_job.open();
  check_bitmap_shows_object(*s.slicer, s.scene->source, job.params().allow_empty);
  {
    py::gil_scoped_release release;
    job.check_fits(*s.slicer);
  }
  const JobStats stats = run_with_progress(py_job, s, progress);
  job.check_result(stats);
  py::dict out;
  py::list layers;
  for (const LayerStats& l : stats.layers) layers.append(stats_dict(l));
  out["layers"] = layers;
  out["total"] = stats_dict(stats.total, LayerStatsPart::kCounts);
  out["padded_layers"] = stats.padded_layers;
  out["seconds"] = stats.seconds;
  out["threads"] = stats.threads;
  out["files"] = stats.files;
  out["layers_kept"] = stats.layers_kept;
  out["interrupted"] = stats.interrupted;
  return out;
}

}  // namespace

void bind_job(py::module_& m) {
  py::class_<PyJob>(m, "_Job")
      .def(py::init(&make_job), py::arg("output_dir"), py::arg("formats"), py::arg("first_layer"),
           py::arg("last_layer"), py::arg("threads"), py::arg("prefix"), py::arg("background"), py::arg("min_layers"),
           py::arg("preview_layers"), py::arg("shard_index"), py::arg("shard_count"), py::arg("resume"),
           py::arg("checks"), py::arg("memory_limit_mb"), py::arg("manifest_interval_seconds"),
           py::arg("construction_cache"), py::arg("allow_empty"))
      .def(
          "read_scene",
          [](PyJob& j, const std::filesystem::path& path) {
            SliceJob& job = j.open();
            py::gil_scoped_release release;
            return SceneHandle{std::make_shared<Scene>(job.read_scene(path))};
          },
          py::arg("path"))
      .def(
          "parse_scene",
          [](PyJob& j, const std::string& text, const std::filesystem::path& source) {
            SliceJob& job = j.open();
            py::gil_scoped_release release;
            return SceneHandle{std::make_shared<Scene>(job.parse_scene(text, source))};
          },
          py::arg("text"), py::arg("source"))
      .def_property_readonly("cache_hits", [](const PyJob& j) { return j.open().cache_hits(); })
      .def_property_readonly("cache_warnings", [](const PyJob& j) { return j.open().cache_warnings(); })
      .def_property_readonly("lock_taken_over_from", [](const PyJob& j) { return j.open().lock_taken_over_from(); })
      .def("run", &run_job, py::arg("slicer"), py::arg("progress"))
      // Rolls the folder back unless run() kept it, and releases the lock (slice_job.h).
      .def("close", [](PyJob& j) {
        py::gil_scoped_release release;
        j.job.reset();
      });
}

}  // namespace trivox::python
