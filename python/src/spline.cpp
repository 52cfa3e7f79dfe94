// Splines and volumes: trivox::TensorSpline as trivox.Spline, trivox::Volume as trivox.Volume
// with its bulk evaluation, Jacobians and both inverse maps (docs/PYTHON.md, "Volumes").
#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <utility>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/parallel.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox::python {

const GlobalSolver& PyVolume::solver() const {
  std::call_once(solver_once_, [this] { solver_ = std::make_unique<GlobalSolver>(volume); });
  return *solver_;
}

Vec3Batch vec3_batch(const py::handle& obj, const char* what) {
  Vec3Batch b{DoubleArray::ensure(obj), {}};
  if (!b.array) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + ": expected an array of numbers");
  }
  if (b.array.ndim() < 1 || b.array.shape(b.array.ndim() - 1) != 3)
    throw py::value_error(std::string(what) + ": expected an array whose last axis has length 3 (shape (N, 3)), got " +
                          std::string(py::str(py::tuple(
                              py::cast(std::vector<py::ssize_t>(b.array.shape(), b.array.shape() + b.array.ndim()))))));
  b.lead.assign(b.array.shape(), b.array.shape() + b.array.ndim() - 1);
  return b;
}

py::array_t<double> new_doubles(const std::vector<py::ssize_t>& lead, std::initializer_list<py::ssize_t> tail) {
  std::vector<py::ssize_t> shape = lead;
  shape.insert(shape.end(), tail.begin(), tail.end());
  return py::array_t<double>(shape);
}

Vec3 to_vec3(const py::handle& obj, const char* what) {
  const std::vector<double> v = py::cast<std::vector<double>>(obj);
  if (v.size() != 3) throw py::value_error(std::string(what) + ": expected three numbers");
  return {v[0], v[1], v[2]};
}

namespace {

// Points per chunk of a batch: large enough that a chunk costs far more than handing it to a
// worker, small enough to share a million points among the cores evenly.
constexpr std::size_t kChunk = 4096;

}  // namespace

void for_chunks(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t)>& body) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: every core)");
  if (n <= kChunk || threads == 1) {
    for (std::size_t b = 0; b < n; b += kChunk) body(b, std::min(n, b + kChunk));
    return;
  }
  // The library's parallel seam (parallel.h), as the slice job uses it.
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  parallel_for_each(chunks, threads, [&](std::size_t c) { body(c * kChunk, std::min(n, (c + 1) * kChunk)); });
}

int direction_index(const py::handle& obj) {
  if (py::isinstance<py::str>(obj)) {
    const std::string s = py::cast<std::string>(obj);
    if (s == "u") return 0;
    if (s == "v") return 1;
    if (s == "w") return 2;
    throw py::value_error("a direction is \"u\", \"v\", \"w\" or 0, 1, 2; got \"" + s + "\"");
  }
  const int d = py::cast<int>(obj);
  if (d < 0 || d > 2) throw py::value_error("a direction is \"u\", \"v\", \"w\" or 0, 1, 2; got " + std::to_string(d));
  return d;
}

namespace {

// --- Spline <-> arrays ---------------------------------------------------------------------

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

// --- Volume bulk calls -------------------------------------------------------------------

// Named tuples of the inverse maps' results (created at import; collections needs no numpy).
py::object g_inversion_type, g_global_inversion_type, g_jacobian_report_type;

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

InverseParams inverse_params(double residual_tolerance_model, int max_iterations, double outside_slack_relative) {
  InverseParams p;
  p.residual_tolerance_model = residual_tolerance_model;
  p.max_iterations = max_iterations;
  p.outside_slack_relative = outside_slack_relative;
  if (!(p.residual_tolerance_model > 0.0)) throw py::value_error("residual_tolerance_model must be > 0");
  if (p.max_iterations < 1) throw py::value_error("max_iterations must be >= 1");
  if (!(p.outside_slack_relative >= 0.0)) throw py::value_error("outside_slack_relative must be >= 0");
  return p;
}

py::object volume_invert(const PyVolume& self, const py::handle& points, const py::handle& hint,
                         double residual_tolerance_model, int max_iterations, double outside_slack_relative,
                         int threads) {
  const InverseParams params = inverse_params(residual_tolerance_model, max_iterations, outside_slack_relative);
  const Vec3Batch x = vec3_batch(points, "points");
  // The hint: one for all points (None: the centre of the domain), or one per point.
  std::optional<Vec3Batch> hints;
  Vec3 one_hint = self.volume.domain().center();
  if (!hint.is_none()) {
    hints = vec3_batch(hint, "hint");
    if (hints->size() == 1 && hints->array.ndim() == 1) {
      one_hint = hints->points()[0];
      hints.reset();
    } else if (hints->lead != x.lead) {
      throw py::value_error("hint: expected one point (shape (3,)) or one per point (the shape of points)");
    }
  }
  py::array_t<double> uvw = new_doubles(x.lead, {3});
  py::array_t<std::uint8_t> status(x.lead);
  py::array_t<double> residual(x.lead);
  py::array_t<std::int32_t> iterations(x.lead);
  const std::span<const Vec3> xs = x.points();
  const Vec3* hs = hints ? hints->points().data() : nullptr;
  Vec3* u = reinterpret_cast<Vec3*>(uvw.mutable_data());
  std::uint8_t* st = status.mutable_data();
  double* r = residual.mutable_data();
  std::int32_t* it = iterations.mutable_data();
  {
    const ReleaseForBatch release(xs.size());
    for_chunks(xs.size(), threads, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const InverseResult res = invert(self.volume, xs[i], hs ? hs[i] : one_hint, params);
        u[i] = res.uvw;
        st[i] = static_cast<std::uint8_t>(res.status);
        r[i] = res.residual;
        it[i] = res.iterations;
      }
    });
  }
  return g_inversion_type(uvw, status, residual, iterations);
}

py::object volume_invert_global(const PyVolume& self, const py::handle& points, double residual_tolerance_model,
                                int max_iterations, double outside_slack_relative, int max_boxes,
                                double same_root_relative, double singular_relative, int threads) {
  GlobalSolveParams params;
  params.newton = inverse_params(residual_tolerance_model, max_iterations, outside_slack_relative);
  params.max_boxes = max_boxes;
  params.same_root_relative = same_root_relative;
  params.singular_relative = singular_relative;
  if (params.max_boxes < 1) throw py::value_error("max_boxes must be >= 1");
  if (!(params.same_root_relative >= 0.0)) throw py::value_error("same_root_relative must be >= 0");
  if (!(params.singular_relative >= 0.0)) throw py::value_error("singular_relative must be >= 0");
  const Vec3Batch x = vec3_batch(points, "points");
  const std::span<const Vec3> xs = x.points();
  const std::size_t n = xs.size();
  py::array_t<std::uint8_t> status(x.lead);
  py::array_t<std::int32_t> boxes(x.lead);
  py::array_t<std::int64_t> offsets(static_cast<py::ssize_t>(n + 1));
  std::uint8_t* st = status.mutable_data();
  std::int32_t* bx = boxes.mutable_data();
  std::int64_t* off = offsets.mutable_data();
  // Each chunk collects its points' preimages in order; the chunks are joined in order after.
  std::vector<std::vector<Preimage>> found((n + kChunk - 1) / kChunk);
  const GlobalSolver* solver = nullptr;
  {
    py::gil_scoped_release release;
    solver = &self.solver();
    for_chunks(n, threads, [&](std::size_t b, std::size_t e) {
      std::vector<Preimage>& mine = found[b / kChunk];
      for (std::size_t i = b; i < e; ++i) {
        const GlobalResult res = solver->solve(xs[i], params);
        st[i] = static_cast<std::uint8_t>(res.status);
        bx[i] = res.boxes_visited;
        off[i + 1] = static_cast<std::int64_t>(res.preimages.size());
        mine.insert(mine.end(), res.preimages.begin(), res.preimages.end());
      }
    });
  }
  off[0] = 0;
  for (std::size_t i = 0; i < n; ++i) off[i + 1] += off[i];
  const auto k = static_cast<py::ssize_t>(off[n]);
  py::array_t<double> uvw({k, py::ssize_t{3}});
  py::array_t<double> residual(k), det(k);
  double* u = uvw.mutable_data();
  double* r = residual.mutable_data();
  double* d = det.mutable_data();
  std::size_t at = 0;
  for (const auto& chunk : found)
    for (const Preimage& p : chunk) {
      u[3 * at] = p.uvw.x;
      u[3 * at + 1] = p.uvw.y;
      u[3 * at + 2] = p.uvw.z;
      r[at] = p.residual;
      d[at] = p.det;
      ++at;
    }
  return g_global_inversion_type(status, offsets, uvw, residual, det, boxes);
}

py::list enum_names(int count, const std::function<std::string_view(int)>& name) {
  py::list out;
  for (int i = 0; i < count; ++i) out.append(std::string(name(i)));
  return out;
}

}  // namespace

// The Spline of a Volume or a Spline (the constructors and refinements take either).
const TensorSpline& spline_of(const py::handle& obj) {
  if (py::isinstance<PyVolume>(obj)) return py::cast<const PyVolume&>(obj).volume.spline();
  return py::cast<const TensorSpline&>(obj);
}

void bind_spline(py::module_& m) {
  py::module_ collections = py::module_::import("collections");
  py::object namedtuple = collections.attr("namedtuple");
  g_inversion_type =
      namedtuple("Inversion", py::make_tuple("uvw", "status", "residual", "iterations"), py::arg("module") = "trivox");
  g_global_inversion_type =
      namedtuple("GlobalInversion", py::make_tuple("status", "offsets", "uvw", "residual", "det", "boxes_visited"),
                 py::arg("module") = "trivox");
  // Kept for the interpreter's lifetime (the module's attributes hold them too).
  g_inversion_type.inc_ref();
  g_global_inversion_type.inc_ref();
  g_inversion_type.attr("__doc__") =
      "Result of Volume.invert, one entry per point: uvw (..., 3) the last Newton iterate (the solution when "
      "status is CONVERGED), status (...) uint8 InverseStatus codes, residual (...) |V(uvw) - x| in model units "
      "(or its certified bound), iterations (...) int32 evaluations of V.";
  g_global_inversion_type.attr("__doc__") =
      "Result of Volume.invert_global: status (...) uint8 GlobalStatus codes and boxes_visited (...) int32 per "
      "point; the preimages of every point in flat arrays: those of point i (in C order of the points' leading "
      "shape) are rows offsets[i]:offsets[i+1] of uvw (K, 3), residual (K,) and det (K,) (det J), sorted by "
      "(u, v, w).";
  m.attr("Inversion") = g_inversion_type;
  m.attr("GlobalInversion") = g_global_inversion_type;
  m.attr("_inverse_status_names") = enum_names(4, [](int i) { return to_string(static_cast<InverseStatus>(i)); });
  m.attr("_global_status_names") = enum_names(5, [](int i) { return to_string(static_cast<GlobalStatus>(i)); });

  py::class_<TensorSpline>(m, "Spline", R"doc(
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
)doc")
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
          "Parametric domain, (param_dim, 2): [lo, hi] per direction.")
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

  py::class_<PyVolume, VolumePtr>(m, "Volume", R"doc(
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
)doc")
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
          "(file, index among the file's trivariates) for a volume read by trivox.read, else None.")
      .def("evaluate", &volume_evaluate, py::arg("params"), py::arg("threads") = 0, py::arg("out") = py::none(),
           "V(u, v, w): params (..., 3) -> points (..., 3). Parameters are clamped to the domain. out: a "
           "C-contiguous float64 array of the result's shape to write into (returned), to reuse one buffer.")
      .def("jacobian", &volume_jacobian, py::arg("params"), py::arg("with_values") = false, py::arg("threads") = 0,
           py::arg("out") = py::none(),
           "Jacobians (..., 3, 3), J[..., r, c] = dV_r / dp_c; with_values=True returns (values, jacobians). out: "
           "the array to write the Jacobians into (with with_values, a pair (values, jacobians)).")
      .def("invert", &volume_invert, py::arg("points"), py::arg("hint") = py::none(), py::kw_only(),
           py::arg("residual_tolerance_model") = InverseParams{}.residual_tolerance_model,
           py::arg("max_iterations") = InverseParams{}.max_iterations,
           py::arg("outside_slack_relative") = InverseParams{}.outside_slack_relative, py::arg("threads") = 0,
           R"doc(
Damped Newton from a hint, kept inside the domain (trivox::invert), for every point:
points (..., 3) in model units; hint None (the domain's centre), one (u, v, w), or one per
point. Returns Inversion(uvw, status, residual, iterations); status holds InverseStatus codes
(CONVERGED, OUTSIDE, NO_CONVERGENCE, SINGULAR). The keyword arguments are InverseParams with
their C++ defaults. Newton finds the preimage near the hint; invert_global finds every one.
)doc")
      .def("invert_global", &volume_invert_global, py::arg("points"), py::kw_only(),
           py::arg("residual_tolerance_model") = InverseParams{}.residual_tolerance_model,
           py::arg("max_iterations") = InverseParams{}.max_iterations,
           py::arg("outside_slack_relative") = InverseParams{}.outside_slack_relative,
           py::arg("max_boxes") = GlobalSolveParams{}.max_boxes,
           py::arg("same_root_relative") = GlobalSolveParams{}.same_root_relative,
           py::arg("singular_relative") = GlobalSolveParams{}.singular_relative, py::arg("threads") = 0,
           R"doc(
Every preimage of every point, or the proof that there is none (trivox::GlobalSolver):
points (..., 3). Returns GlobalInversion(status, offsets, uvw, residual, det, boxes_visited);
status holds GlobalStatus codes (NONE, UNIQUE, MULTIPLE, DEGENERATE, INCOMPLETE); the
preimages of point i are rows offsets[i]:offsets[i+1] of uvw, residual and det. The keyword
arguments are GlobalSolveParams (its Newton's InverseParams first) with their C++ defaults.
The solver is built on the first call and kept with the volume.
)doc")
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

  g_jacobian_report_type = namedtuple(
      "JacobianReport", py::make_tuple("classification", "positive", "negative", "zero", "min_det", "max_det"),
      py::arg("module") = "trivox");
  g_jacobian_report_type.inc_ref();
  m.attr("JacobianReport") = g_jacobian_report_type;
}

}  // namespace trivox::python
