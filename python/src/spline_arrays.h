// Splines and numpy arrays both ways, shared by the Spline and Volume bindings (spline.cpp,
// volume.cpp): a spline from orders, knots and control values (flat or as a grid), and its
// control points, weights and knots as arrays.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bindings.h"

namespace trivox::python {

// The Spline(orders, knots, points, weights=None, periodic=None) constructor's work; raises
// ValueError (shapes) or ModelError (the spline's rules).
TensorSpline make_spline(const std::vector<int>& orders, const std::vector<std::vector<double>>& knots,
                         const py::object& points, const py::object& weights,
                         const std::optional<std::vector<bool>>& periodic);

// (N, dim), u fastest: the storage, as the scene file lists control points.
py::array_t<double> flat_points(const TensorSpline& s);
// The control points (or, with `weights`, the weights) as a grid indexed [i, j, k, c].
py::array_t<double> grid_points(const TensorSpline& s, bool weights);
// The weights (N,), u fastest, or None.
py::object flat_weights(const TensorSpline& s);
py::list knot_arrays(const TensorSpline& s);
std::vector<int> orders_of(const TensorSpline& s);
// The same knots, points and weights, bit for bit.
bool same_spline(const TensorSpline& a, const TensorSpline& b);
// The repr: "<trivox.cls ...>".
std::string describe(const TensorSpline& s, const char* cls);
// Parameters of the spline's general evaluator: (..., param_dim) -> (..., point_dim).
py::array_t<double> spline_evaluate(const TensorSpline& s, const py::handle& params, bool partials);

// The Volume class (volume.cpp); its inverse maps are bound by bind_volume_inverse
// (volume_inverse.cpp), with the named tuples they return.
using VolumeClass = py::class_<PyVolume, VolumePtr>;
void bind_volume(py::module_& m);
void bind_volume_inverse(py::module_& m, VolumeClass& volume);

}  // namespace trivox::python
