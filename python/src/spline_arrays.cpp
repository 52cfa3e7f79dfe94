// Splines and numpy arrays both ways (spline_arrays.h).
#include "spline_arrays.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>

#include "trivox/error.h"

namespace trivox::python {

namespace {

std::vector<KnotVector> make_knots(const std::vector<int>& orders, const std::vector<std::vector<double>>& knots,
                                   const std::optional<std::vector<bool>>& periodic) {
  if (orders.empty() || orders.size() > 3)
    throw py::value_error("a spline has 1 to 3 parametric directions: give 1 to 3 orders");
  if (knots.size() != orders.size())
    throw py::value_error("give one knot vector per order (" + std::to_string(orders.size()) + "), got " +
                          std::to_string(knots.size()));
  if (periodic && periodic->size() != orders.size())
    throw py::value_error("give one periodic flag per order (" + std::to_string(orders.size()) + ")");
  std::vector<KnotVector> out;
  for (std::size_t d = 0; d < orders.size(); ++d) {
    if (periodic && (*periodic)[d]) {
      // IRIT's periodic vector: num_ctrl + 2 * order - 1 knots.
      const int n = static_cast<int>(knots[d].size()) - 2 * orders[d] + 1;
      out.push_back(KnotVector::periodic(orders[d], n, knots[d]));
    } else {
      out.emplace_back(orders[d], knots[d]);
    }
  }
  return out;
}

std::vector<py::ssize_t> ctrl_counts(const std::vector<KnotVector>& kv) {
  std::vector<py::ssize_t> n;
  for (const KnotVector& k : kv) n.push_back(k.num_ctrl());
  return n;
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// Control values u fastest, from a flat (N, dim) or (N,) array or a grid (n0, ..., dim) or
// (n0, ...) indexed [i, j, k]. `dim` receives the point dimension (1 for a grid of scalars).
std::vector<double> gather(const py::handle& obj, const std::vector<py::ssize_t>& n, bool with_dim, int& dim,
                           const char* what) {
  const DoubleArray a = DoubleArray::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + ": expected an array of numbers");
  }
  py::ssize_t total = 1;
  for (py::ssize_t k : n) total *= k;
  const auto p = static_cast<py::ssize_t>(n.size());
  const double* src = a.data();
  auto grid_matches = [&](py::ssize_t ndim) {
    if (a.ndim() != ndim) return false;
    for (py::ssize_t d = 0; d < p; ++d)
      if (a.shape(d) != n[static_cast<std::size_t>(d)]) return false;
    return true;
  };
  std::vector<double> out;
  if (a.ndim() >= 1 && a.shape(0) == total && (a.ndim() == 1 || (with_dim && a.ndim() == 2))) {
    dim = a.ndim() == 1 ? 1 : static_cast<int>(a.shape(1));  // flat: already u fastest
    out.assign(src, src + a.size());
    return out;
  }
  const bool grid_dim = with_dim && grid_matches(p + 1);
  if (grid_dim || grid_matches(p)) {
    dim = grid_dim ? static_cast<int>(a.shape(p)) : 1;
    const std::array<py::ssize_t, 3> m{n[0], p > 1 ? n[1] : 1, p > 2 ? n[2] : 1};
    out.resize(static_cast<std::size_t>(a.size()));
    std::size_t at = 0;
    // C order of the grid: index ((i * m1 + j) * m2 + k) * dim + c; the output runs u fastest.
    for (py::ssize_t k = 0; k < m[2]; ++k)
      for (py::ssize_t j = 0; j < m[1]; ++j)
        for (py::ssize_t i = 0; i < m[0]; ++i)
          for (int c = 0; c < dim; ++c) out[at++] = src[((i * m[1] + j) * m[2] + k) * dim + c];
    return out;
  }
  std::string grid = "(";
  for (std::size_t d = 0; d < n.size(); ++d) grid += (d ? ", " : "") + std::to_string(n[d]);
  throw py::value_error(std::string(what) + ": the knots and orders make " + std::to_string(total) +
                        " control points, a grid " + grid + "); expected shape (" + std::to_string(total) +
                        (with_dim ? ", dim)" : ",)") + " (u fastest) or " + grid + (with_dim ? ", dim)" : ")") +
                        ", got " + shape_text(a));
}

}  // namespace

TensorSpline make_spline(const std::vector<int>& orders, const std::vector<std::vector<double>>& knots,
                         const py::object& points, const py::object& weights,
                         const std::optional<std::vector<bool>>& periodic) {
  std::vector<KnotVector> kv = make_knots(orders, knots, periodic);
  const std::vector<py::ssize_t> n = ctrl_counts(kv);
  int dim = 0;
  std::vector<double> pts = gather(points, n, true, dim, "points");
  std::vector<double> w;
  if (!weights.is_none()) {
    int one = 0;
    w = gather(weights, n, false, one, "weights");
    if (one != 1) throw py::value_error("weights: one weight per control point");
  }
  return TensorSpline(std::move(kv), dim, std::move(pts), std::move(w));
}

// (N, dim), u fastest: the storage, as the scene file lists control points.
py::array_t<double> flat_points(const TensorSpline& s) {
  py::array_t<double> a({static_cast<py::ssize_t>(s.total_ctrl()), static_cast<py::ssize_t>(s.point_dim())});
  std::memcpy(a.mutable_data(), s.points().data(), s.points().size() * sizeof(double));
  return a;
}

// The same values as a grid indexed [i, j, k, c] (strides of the u-fastest storage).
py::array_t<double> grid_points(const TensorSpline& s, bool weights) {
  std::vector<py::ssize_t> shape, strides;
  py::ssize_t stride = weights ? py::ssize_t{sizeof(double)} : py::ssize_t{sizeof(double)} * s.point_dim();
  for (int d = 0; d < s.param_dim(); ++d) {
    shape.push_back(s.num_ctrl(d));
    strides.push_back(stride);
    stride *= s.num_ctrl(d);
  }
  if (!weights) {
    shape.push_back(s.point_dim());
    strides.push_back(sizeof(double));
  }
  py::array_t<double> a(shape, strides);
  const std::span<const double> src = weights ? s.weights() : s.points();
  std::memcpy(a.mutable_data(), src.data(), src.size() * sizeof(double));
  return a;
}

py::object flat_weights(const TensorSpline& s) {
  if (!s.is_rational()) return py::none();
  py::array_t<double> a(static_cast<py::ssize_t>(s.weights().size()));
  std::memcpy(a.mutable_data(), s.weights().data(), s.weights().size() * sizeof(double));
  return a;
}

py::list knot_arrays(const TensorSpline& s) {
  py::list out;
  for (const KnotVector& k : s.all_knots()) {
    py::array_t<double> a(static_cast<py::ssize_t>(k.knots().size()));
    std::memcpy(a.mutable_data(), k.knots().data(), k.knots().size() * sizeof(double));
    out.append(a);
  }
  return out;
}

std::vector<int> orders_of(const TensorSpline& s) {
  std::vector<int> o;
  for (const KnotVector& k : s.all_knots()) o.push_back(k.order());
  return o;
}

bool same_spline(const TensorSpline& a, const TensorSpline& b) {
  return a.all_knots() == b.all_knots() && a.point_dim() == b.point_dim() &&
         std::equal(a.points().begin(), a.points().end(), b.points().begin(), b.points().end()) &&
         std::equal(a.weights().begin(), a.weights().end(), b.weights().begin(), b.weights().end());
}

std::string describe(const TensorSpline& s, const char* cls) {
  std::string o, n;
  for (int d = 0; d < s.param_dim(); ++d) {
    o += (d ? ", " : "") + std::to_string(s.knots(d).order());
    n += (d ? " x " : "") + std::to_string(s.num_ctrl(d));
  }
  return std::string("<trivox.") + cls + " orders (" + o + "), " + n + " control points of dimension " +
         std::to_string(s.point_dim()) + (s.is_rational() ? ", rational" : "") + ">";
}

// Parameters of the spline's general evaluator: (..., param_dim) -> (..., point_dim).
py::array_t<double> spline_evaluate(const TensorSpline& s, const py::handle& params, bool partials) {
  const DoubleArray a = DoubleArray::ensure(params);
  if (!a) {
    PyErr_Clear();
    throw py::type_error("params: expected an array of numbers");
  }
  const int p = s.param_dim(), dim = s.point_dim();
  if (a.ndim() < 1 || a.shape(a.ndim() - 1) != p)
    throw py::value_error("params: expected an array whose last axis has length " + std::to_string(p) + ", got " +
                          shape_text(a));
  std::vector<py::ssize_t> shape(a.shape(), a.shape() + a.ndim() - 1);
  const auto n = static_cast<std::size_t>(a.size() / p);
  if (partials) shape.push_back(p);
  shape.push_back(dim);
  py::array_t<double> out(shape);
  double* o = out.mutable_data();
  const double* t = a.data();
  {
    py::gil_scoped_release release;
    std::vector<double> value(static_cast<std::size_t>(dim));
    for (std::size_t i = 0; i < n; ++i) {
      const std::span<const double> ti(t + i * static_cast<std::size_t>(p), static_cast<std::size_t>(p));
      if (partials)
        s.evaluate_with_partials(
            ti, value, std::span<double>(o + i * static_cast<std::size_t>(p * dim), static_cast<std::size_t>(p * dim)));
      else
        s.evaluate(ti, std::span<double>(o + i * static_cast<std::size_t>(dim), static_cast<std::size_t>(dim)));
    }
  }
  return out;
}

}  // namespace trivox::python
