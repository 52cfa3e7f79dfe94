// Splines: trivox::TensorSpline as trivox.Spline, its arrays, evaluation and the exact changes
// of space (docs/PYTHON.md, "Volumes"); the Volume class is in volume.cpp.
#include <span>
#include <string>
#include <vector>

#include "bindings.h"
#include "spline_arrays.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox::python {

namespace {

// The Spline class: construction, its arrays and evaluation.
py::class_<TensorSpline> bind_spline_class(py::module_& m) {
  py::class_<TensorSpline> spline(m, "Spline", R"doc(
A B-spline or NURBS curve, surface or trivariate of any order and point dimension
(trivox::TensorSpline). Geometry has point dimension 3; a material field with k components
dimension k.

Spline(orders, knots, points, weights=None, periodic=None)

orders: one order (degree + 1) per parametric direction (1 to 3 directions); knots: one full
knot vector per direction (n + order knots for n control points, non-decreasing); points: the
control points, either flat (N, dim) with u fastest, then v, then w (the scene file's order),
or as a grid (n_u, n_v, n_w, dim) indexed [i, j, k]; a scalar field may leave out the last
axis. weights: one weight > 0 per control point (flat or grid), Euclidean points (not
pre-multiplied); None for a polynomial spline. periodic: per direction, True for IRIT's
periodic knot vectors (n + 2 order - 1 knots). Raises ModelError naming the rule broken.
)doc");
  spline
      .def(py::init(&make_spline), py::arg("orders"), py::arg("knots"), py::arg("points"),
           py::arg("weights") = py::none(), py::arg("periodic") = py::none())
      .def_property_readonly("param_dim", &TensorSpline::param_dim, "Parametric directions (1, 2 or 3).")
      .def_property_readonly("point_dim", &TensorSpline::point_dim, "Coordinates per control point.")
      .def_property_readonly("is_rational", &TensorSpline::is_rational, "True for a NURBS (weights given).")
      .def_property_readonly("orders", &orders_of, "Order (degree + 1) per direction.")
      .def_property_readonly("knots", &knot_arrays, "Full knot vector per direction (float64 arrays, copies).")
      .def_property_readonly(
          "periodic",
          [](const TensorSpline& s) {
            std::vector<bool> p;
            for (const KnotVector& k : s.all_knots()) p.push_back(k.is_periodic());
            return p;
          },
          "Per direction, whether its knot vector is periodic (IRIT's KVP).")
      .def_property_readonly(
          "num_ctrl",
          [](const TensorSpline& s) {
            std::vector<int> n;
            for (int d = 0; d < s.param_dim(); ++d) n.push_back(s.num_ctrl(d));
            return py::tuple(py::cast(n));
          },
          "Distinct control points per direction.")
      .def_property_readonly("points", &flat_points,
                             "Control points (N, point_dim), u fastest (a copy; the scene file's order).")
      .def_property_readonly(
          "control_grid", [](const TensorSpline& s) { return grid_points(s, false); },
          "Control points as a grid (n_u, n_v, n_w, point_dim) indexed [i, j, k] (a copy).")
      .def_property_readonly("weights", &flat_weights, "Weights (N,), u fastest, or None for a polynomial spline.")
      .def_property_readonly(
          "weight_grid",
          [](const TensorSpline& s) -> py::object {
            if (!s.is_rational()) return py::none();
            return grid_points(s, true);
          },
          "Weights as a grid (n_u, n_v, n_w), or None.")
      .def_property_readonly(
          "domain",
          [](const TensorSpline& s) {
            py::array_t<double> d({static_cast<py::ssize_t>(s.param_dim()), py::ssize_t{2}});
            for (int k = 0; k < s.param_dim(); ++k) {
              d.mutable_at(k, 0) = s.lo(k);
              d.mutable_at(k, 1) = s.hi(k);
            }
            return d;
          },
          "Parametric domain, (param_dim, 2): [lo, hi] per direction.");
  return spline;
}

// Knot insertion, splitting, degree elevation, changes of direction and affine maps.
void bind_spline_refinement(py::class_<TensorSpline>& spline) {
  spline
      .def(
          "control_box",
          [](const TensorSpline& s) {
            const Box3 b = s.control_box();
            return py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z), py::make_tuple(b.hi.x, b.hi.y, b.hi.z));
          },
          "((x, y, z) lo, (x, y, z) hi): the box of the Euclidean control points (first three coordinates).")
      .def(
          "evaluate", [](const TensorSpline& s, const py::handle& t) { return spline_evaluate(s, t, false); },
          py::arg("params"),
          "Values at params (..., param_dim) -> (..., point_dim), by the general evaluator (the reference the "
          "fast Volume kernels are tested against). Parameters are clamped to the domain.")
      .def(
          "partials", [](const TensorSpline& s, const py::handle& t) { return spline_evaluate(s, t, true); },
          py::arg("params"), "First partial derivatives (..., param_dim, point_dim): [..., d, c] = d out_c / d t_d.")
      .def(
          "insert_knot",
          [](const TensorSpline& s, const py::handle& dir, double t, int times) {
            return insert_knot(s, direction_index(dir), t, times);
          },
          py::arg("dir"), py::arg("t"), py::arg("times") = 1,
          "Inserts knot t `times` times along dir (0-2 or 'u', 'v', 'w'); the geometry is unchanged.")
      .def(
          "split",
          [](const TensorSpline& s, const py::handle& dir, double t) { return split(s, direction_index(dir), t); },
          py::arg("dir"), py::arg("t"), "The parts over [lo, t] and [t, hi] along dir.")
      .def(
          "elevate_degree",
          [](const TensorSpline& s, const py::handle& dir, int times) {
            return elevate_degree(s, direction_index(dir), times);
          },
          py::arg("dir"), py::arg("times") = 1, "Raises the degree along dir by `times`, exactly.")
      .def(
          "clamped", [](const TensorSpline& s) { return clamped(s); },
          "The same geometry with every direction clamped (periodic ones unwrapped).")
      .def(
          "reparametrized",
          [](const TensorSpline& s, const py::handle& dir, double lo, double hi) {
            return reparametrized(s, direction_index(dir), lo, hi);
          },
          py::arg("dir"), py::arg("lo"), py::arg("hi"), "The domain along dir mapped affinely onto [lo, hi].")
      .def(
          "reversed", [](const TensorSpline& s, const py::handle& dir) { return reversed(s, direction_index(dir)); },
          py::arg("dir"), "Direction dir reversed (t -> lo + hi - t).")
      .def(
          "permuted",
          [](const TensorSpline& s, const std::vector<py::object>& order) {
            std::vector<int> o;
            for (const auto& d : order) o.push_back(direction_index(d));
            return permuted(s, o);
          },
          py::arg("order"), "Direction d of the result is direction order[d] of this spline.")
      .def(
          "bezier_patches", [](const TensorSpline& s) { return bezier_patches(s); },
          "The polynomial pieces as Bezier patches, u fastest.")
      .def(
          "transformed",
          [](const TensorSpline& s, const py::handle& matrix) {
            const DoubleArray a = DoubleArray::ensure(matrix);
            if (!a || a.ndim() != 2 || a.shape(1) != 4 || (a.shape(0) != 3 && a.shape(0) != 4))
              throw py::value_error("matrix: expected a 3 x 4 or 4 x 4 affine matrix (rows)");
            if (s.point_dim() != 3) throw py::value_error("only splines with 3D points can be transformed");
            const double* q = a.data();
            return s.transformed([q](std::span<double> p) {
              const double x = p[0], y = p[1], z = p[2];
              for (int r = 0; r < 3; ++r)
                p[static_cast<std::size_t>(r)] = q[4 * r] * x + q[4 * r + 1] * y + q[4 * r + 2] * z + q[4 * r + 3];
            });
          },
          py::arg("matrix"),
          "The spline with the affine map (a 3 x 4 or 4 x 4 matrix, rows) applied to its control points; exact "
          "for B-splines and NURBS (weights kept).")
      .def("__eq__", [](const TensorSpline& a, const TensorSpline& b) { return same_spline(a, b); })
      .def("__repr__", [](const TensorSpline& s) { return describe(s, "Spline"); });
}

}  // namespace

void bind_spline(py::module_& m) {
  py::class_<TensorSpline> spline = bind_spline_class(m);
  bind_spline_refinement(spline);
  bind_volume(m);
}

}  // namespace trivox::python
