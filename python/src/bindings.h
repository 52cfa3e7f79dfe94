// Shared pieces of the Python module's bindings (docs/PYTHON.md): one bind_* function per
// area, the wrappers that give library objects a Python lifetime, and the conversions between
// numpy arrays and the library's value types.
//
// Every array in or out is numpy: batches of points are arrays whose last axis holds the three
// coordinates (any leading shape), converted once to contiguous float64 and handed to the
// library as spans of Vec3, so no Python loop ever runs per point.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trivox/inverse/invert.h"
#include "trivox/math.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slice_stats.h"
#include "trivox/slice/slicer.h"
#include "trivox/spline/tensor_spline.h"
#include "trivox/spline/volume.h"

namespace trivox::python {

namespace py = pybind11;

// A contiguous float64 array (a copy only when the input is not one already).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A volume with what the Python side adds: where it came from (a model file and the index of
// the trivariate among the file's trivariates, so that a scene can name the file instead of
// copying the control points) and the global solver, built on first use and then shared by
// every call (GlobalSolver::solve is const and thread-safe). Held by shared_ptr: the solver
// keeps a pointer to `volume`, which therefore never moves.
struct PyVolume {
  explicit PyVolume(Volume v) : volume(std::move(v)) {}
  PyVolume(const PyVolume&) = delete;
  PyVolume& operator=(const PyVolume&) = delete;

  const GlobalSolver& solver() const;

  Volume volume;
  std::string source_file;  // absolute path, empty when made in Python or by a constructor
  int source_patch = -1;    // index among the file's trivariates

 private:
  mutable std::once_flag solver_once_;
  mutable std::unique_ptr<GlobalSolver> solver_;
};
using VolumePtr = std::shared_ptr<PyVolume>;

// A scene (the library's, immutable once read) shared by the Python objects that use it: a
// slicer keeps a reference to its scene, so both hold this pointer.
using ScenePtr = std::shared_ptr<const Scene>;
struct SceneHandle {
  ScenePtr scene;
};

// The library's slicer and the scene it keeps a reference to (trivox._Slicer).
struct PySlicer {
  ScenePtr scene;
  std::unique_ptr<Slicer> slicer;
  // The slicer's stop flag (SliceParams::stop): a job raises it with its own on Ctrl-C, so that
  // the layers in progress end within a row (job.cpp); lowered when a job or a layer starts.
  mutable std::atomic<bool> stop{false};
};

// A layer's counts (or a job's sum) as a dict with stats.json's names (visit_layer_stats);
// `part` kLayer adds the layer's index, height and times.
py::dict stats_dict(const LayerStats& s, LayerStatsPart part = LayerStatsPart::kLayer);

// A batch of 3-vectors: an array whose last axis has length 3. `lead` receives the shape
// before that axis. Throws ValueError naming `what` otherwise.
struct Vec3Batch {
  DoubleArray array;
  std::vector<py::ssize_t> lead;
  std::span<const Vec3> points() const {
    return {reinterpret_cast<const Vec3*>(array.data()), static_cast<std::size_t>(array.size() / 3)};
  }
  std::size_t size() const { return static_cast<std::size_t>(array.size() / 3); }
};
Vec3Batch vec3_batch(const py::handle& obj, const char* what);

// A new float64 array of shape lead + tail.
py::array_t<double> new_doubles(const std::vector<py::ssize_t>& lead, std::initializer_list<py::ssize_t> tail);

// Releases the GIL for the bulk work on n points when it is worth it: below kGilBatch points
// the work takes less time than handing the GIL to another thread and taking it back (which
// can wait for the other thread's switch interval), so small calls keep it.
inline constexpr std::size_t kGilBatch = 64;
class ReleaseForBatch {
 public:
  explicit ReleaseForBatch(std::size_t n) {
    if (n >= kGilBatch) release_.emplace();
  }

 private:
  std::optional<py::gil_scoped_release> release_;
};

// One Vec3 from any sequence of three numbers.
Vec3 to_vec3(const py::handle& obj, const char* what);

// Points per chunk of a batch (for_chunks): large enough that a chunk costs far more than
// handing it to a worker, small enough to share a million points among the cores evenly.
inline constexpr std::size_t kChunk = 4096;

// Runs body(begin, end) over [0, n) in chunks, on `threads` workers (0: every core) when the
// batch is large enough to pay for the threads, else on the calling thread. Every chunk's
// result depends only on its own indices, so the output is the same for any thread count.
void for_chunks(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t)>& body);

// The spline of a Volume or a Spline (constructors and refinements take either).
const TensorSpline& spline_of(const py::handle& obj);

// The scene-file name of a parametric direction: 0 -> "u".
int direction_index(const py::handle& obj);

void bind_errors(py::module_& m);
void bind_spline(py::module_& m);
void bind_model(py::module_& m);
void bind_construct(py::module_& m);
void bind_scene(py::module_& m);
void bind_slice(py::module_& m);
void bind_job(py::module_& m);

}  // namespace trivox::python
