// Volumes: trivox::Volume as trivox.Volume, with its bulk evaluation and Jacobians (docs/PYTHON.md,
// "Volumes"); its inverse maps are in volume_inverse.cpp.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "bindings.h"
#include "spline_arrays.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox::python {

const GlobalSolver& PyVolume::solver() const {
  std::call_once(solver_once_, [this] { solver_ = std::make_unique<GlobalSolver>(volume); });
  return *solver_;
}

namespace {

// --- Bulk calls ---------------------------------------------------------------------------

// The named tuple of check_jacobian (created at import; collections needs no numpy).
py::object g_jacobian_report_type;

// The output array: a new one, or `out` when given, which must be a writable contiguous
// float64 array of the result's shape (so that a caller can reuse its buffers).
py::array_t<double> output(const py::object& out, const std::vector<py::ssize_t>& lead,
                           std::initializer_list<py::ssize_t> tail, const char* what) {
  if (out.is_none()) return new_doubles(lead, tail);
  std::vector<py::ssize_t> shape = lead;
  shape.insert(shape.end(), tail.begin(), tail.end());
  if (!py::isinstance<py::array_t<double>>(out))
    throw py::type_error(std::string(what) + ": expected a float64 numpy array");
  auto a = py::reinterpret_borrow<py::array_t<double>>(out);
  const bool contiguous = (a.flags() & py::array::c_style) != 0;
  if (!contiguous || !a.writeable() || a.ndim() != static_cast<py::ssize_t>(shape.size()) ||
      !std::equal(shape.begin(), shape.end(), a.shape()))
    throw py::value_error(std::string(what) +
                          ": expected a writable C-contiguous float64 array of the result's shape "
                          "(the leading shape of params, then the result's axes)");
  return a;
}

py::array_t<double> volume_evaluate(const PyVolume& self, const py::handle& params, int threads,
                                    const py::object& out_arg) {
  const Vec3Batch in = vec3_batch(params, "params");
  py::array_t<double> out = output(out_arg, in.lead, {3}, "out");
  const std::span<const Vec3> p = in.points();
  Vec3* o = reinterpret_cast<Vec3*>(out.mutable_data());
  {
    const ReleaseForBatch release(p.size());
    for_chunks(p.size(), threads, [&](std::size_t b, std::size_t e) {
      self.volume.evaluate_many(p.subspan(b, e - b), std::span<Vec3>(o + b, e - b));
    });
  }
  return out;
}

py::object volume_jacobian(const PyVolume& self, const py::handle& params, bool with_values, int threads,
                           const py::object& out_arg) {
  const Vec3Batch in = vec3_batch(params, "params");
  py::object values_out = py::none(), jacobian_out = out_arg;
  if (with_values && !out_arg.is_none()) {
    const auto pair = py::cast<std::pair<py::object, py::object>>(out_arg);
    values_out = pair.first;
    jacobian_out = pair.second;
  }
  py::array_t<double> jac = output(jacobian_out, in.lead, {3, 3}, "out");
  const std::span<const Vec3> p = in.points();
  // Mat3 is three rows of three doubles: the array's (3, 3) rows, J[r, c] = dV_r / dp_c.
  static_assert(sizeof(Mat3) == 9 * sizeof(double));
  Mat3* j = reinterpret_cast<Mat3*>(jac.mutable_data());
  if (!with_values) {
    // evaluate_jacobian point by point is evaluate_jacobian_many's definition; the values are
    // not kept, so they need no array.
    const ReleaseForBatch release(p.size());
    for_chunks(p.size(), threads, [&](std::size_t b, std::size_t e) {
      Vec3 value;
      for (std::size_t i = b; i < e; ++i) self.volume.evaluate_jacobian(p[i], value, j[i]);
    });
    return jac;
  }
  py::array_t<double> values = output(values_out, in.lead, {3}, "out[0]");
  Vec3* v = reinterpret_cast<Vec3*>(values.mutable_data());
  {
    const ReleaseForBatch release(p.size());
    for_chunks(p.size(), threads, [&](std::size_t b, std::size_t e) {
      self.volume.evaluate_jacobian_many(p.subspan(b, e - b), std::span<Vec3>(v + b, e - b),
                                         std::span<Mat3>(j + b, e - b));
    });
  }
  return py::make_tuple(values, jac);
}

// The Volume class: construction and its arrays.
VolumeClass bind_volume_class(py::module_& m) {
  VolumeClass volume(m, "Volume", R"doc(
A trivariate with 3D control points, B-spline or NURBS (trivox::Volume): the geometry of a
cell, with the fast evaluators the slicer runs per voxel.

Volume(orders, knots, points, weights=None, periodic=None, *, power_form=True)
Volume(spline, *, power_form=True)

The arguments are those of Spline (three directions, point dimension 3). power_form=False
keeps the de Boor kernel even where the power form would be used.
Every bulk call takes an array whose last axis has length 3 (any leading shape), releases the
GIL (for 64 points or more) and runs over the points on `threads` workers (0: every core;
batches of up to 4096 points run on the calling thread), with the same bits for any thread
count.
)doc");
  volume
      .def(py::init([](const TensorSpline& s, bool power_form) {
             VolumeOptions o;
             o.power_form = power_form;
             return std::make_shared<PyVolume>(Volume(s, o));
           }),
           py::arg("spline"), py::kw_only(), py::arg("power_form") = true)
      .def(py::init([](const std::vector<int>& orders, const std::vector<std::vector<double>>& knots,
                       const py::object& points, const py::object& weights,
                       const std::optional<std::vector<bool>>& periodic, bool power_form) {
             VolumeOptions o;
             o.power_form = power_form;
             return std::make_shared<PyVolume>(Volume(make_spline(orders, knots, points, weights, periodic), o));
           }),
           py::arg("orders"), py::arg("knots"), py::arg("points"), py::arg("weights") = py::none(),
           py::arg("periodic") = py::none(), py::kw_only(), py::arg("power_form") = true)
      .def_property_readonly(
          "spline", [](const PyVolume& v) { return v.volume.spline(); }, "The trivariate as a Spline (a copy).")
      .def_property_readonly(
          "orders", [](const PyVolume& v) { return orders_of(v.volume.spline()); }, "Orders (u, v, w).")
      .def_property_readonly(
          "knots", [](const PyVolume& v) { return knot_arrays(v.volume.spline()); }, "Knot vectors (u, v, w).")
      .def_property_readonly(
          "periodic",
          [](const PyVolume& v) {
            std::vector<bool> p;
            for (const KnotVector& k : v.volume.spline().all_knots()) p.push_back(k.is_periodic());
            return p;
          },
          "Per direction, whether its knot vector is periodic.")
      .def_property_readonly(
          "num_ctrl",
          [](const PyVolume& v) {
            const TensorSpline& s = v.volume.spline();
            return py::make_tuple(s.num_ctrl(0), s.num_ctrl(1), s.num_ctrl(2));
          },
          "Control points per direction.")
      .def_property_readonly(
          "points", [](const PyVolume& v) { return flat_points(v.volume.spline()); },
          "Control points (N, 3), u fastest (a copy).")
      .def_property_readonly(
          "control_grid", [](const PyVolume& v) { return grid_points(v.volume.spline(), false); },
          "Control points (n_u, n_v, n_w, 3) indexed [i, j, k] (a copy).")
      .def_property_readonly(
          "weights", [](const PyVolume& v) { return flat_weights(v.volume.spline()); },
          "Weights (N,) u fastest, or None.")
      .def_property_readonly(
          "weight_grid",
          [](const PyVolume& v) -> py::object {
            if (!v.volume.spline().is_rational()) return py::none();
            return grid_points(v.volume.spline(), true);
          },
          "Weights (n_u, n_v, n_w), or None.")
      .def_property_readonly(
          "is_rational", [](const PyVolume& v) { return v.volume.spline().is_rational(); }, "True for a NURBS.")
      .def_property_readonly(
          "domain",
          [](const PyVolume& v) {
            const ParamBox& d = v.volume.domain();
            py::array_t<double> a({py::ssize_t{3}, py::ssize_t{2}});
            for (int k = 0; k < 3; ++k) {
              a.mutable_at(k, 0) = d.lo[k];
              a.mutable_at(k, 1) = d.hi[k];
            }
            return a;
          },
          "Parametric domain (3, 2): [lo, hi] for u, v, w.")
      .def_property_readonly(
          "bounds",
          [](const PyVolume& v) {
            const Box3& b = v.volume.bounds();
            py::array_t<double> a({py::ssize_t{2}, py::ssize_t{3}});
            for (int k = 0; k < 3; ++k) {
              a.mutable_at(0, k) = b.lo[k];
              a.mutable_at(1, k) = b.hi[k];
            }
            return a;
          },
          "(2, 3): the box [lo, hi] of the control points, which holds the whole volume (mm in a scene).")
      .def_property_readonly(
          "kernel",
          [](const PyVolume& v) {
            return std::string(v.volume.kernel() == VolumeKernel::kPowerForm ? "power_form" : "de_boor");
          },
          "The evaluator chosen: 'power_form' (orders 2-4) or 'de_boor'.")
      .def_property_readonly(
          "source",
          [](const PyVolume& v) -> py::object {
            if (v.source_file.empty()) return py::none();
            return py::make_tuple(v.source_file, v.source_patch);
          },
          "(file, index among the file's trivariates) for a volume read by trivox.read, else None.");
  return volume;
}

// Evaluation, Jacobians and the Jacobian check.
void bind_volume_evaluation(py::module_& m, VolumeClass& volume) {
  volume
      .def("evaluate", &volume_evaluate, py::arg("params"), py::arg("threads") = 0, py::arg("out") = py::none(),
           "V(u, v, w): params (..., 3) -> points (..., 3). Parameters are clamped to the domain. out: a "
           "C-contiguous float64 array of the result's shape to write into (returned), to reuse one buffer.")
      .def("jacobian", &volume_jacobian, py::arg("params"), py::arg("with_values") = false, py::arg("threads") = 0,
           py::arg("out") = py::none(),
           "Jacobians (..., 3, 3), J[..., r, c] = dV_r / dp_c; with_values=True returns (values, jacobians). out: "
           "the array to write the Jacobians into (with with_values, a pair (values, jacobians)).")
      .def(
          "check_jacobian",
          [](const PyVolume& v, int samples_per_direction, double zero_relative) {
            JacobianCheckParams p;
            p.samples_per_direction = samples_per_direction;
            p.zero_relative = zero_relative;
            if (p.samples_per_direction < 2) throw py::value_error("samples_per_direction must be >= 2");
            JacobianReport r;
            {
              py::gil_scoped_release release;
              r = check_jacobian(v.volume, p);
            }
            return g_jacobian_report_type(std::string(to_string(r.classification)), r.positive, r.negative, r.zero,
                                          r.min_det, r.max_det);
          },
          py::arg("samples_per_direction") = JacobianCheckParams{}.samples_per_direction,
          py::arg("zero_relative") = JacobianCheckParams{}.zero_relative,
          "The sampled Jacobian check (trivox info's): JacobianReport(classification, positive, negative, zero, "
          "min_det, max_det); classification is 'right-handed', 'left-handed', 'degenerate' or 'folded'.")
      .def("__eq__",
           [](const PyVolume& a, const PyVolume& b) { return same_spline(a.volume.spline(), b.volume.spline()); })
      .def("__repr__", [](const PyVolume& v) { return describe(v.volume.spline(), "Volume"); });

  py::module_ collections = py::module_::import("collections");
  py::object namedtuple = collections.attr("namedtuple");
  g_jacobian_report_type = namedtuple(
      "JacobianReport", py::make_tuple("classification", "positive", "negative", "zero", "min_det", "max_det"),
      py::arg("module") = "trivox");
  g_jacobian_report_type.inc_ref();
  m.attr("JacobianReport") = g_jacobian_report_type;
}

}  // namespace

void bind_volume(py::module_& m) {
  VolumeClass volume = bind_volume_class(m);
  bind_volume_evaluation(m, volume);
  bind_volume_inverse(m, volume);
}

}  // namespace trivox::python
