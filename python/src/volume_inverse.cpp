// The inverse maps of a Volume in bulk: Volume.invert (Newton from a hint) and
// Volume.invert_global (every preimage), with the named tuples they return (docs/PYTHON.md,
// "Volumes").
#include <string>
#include <vector>

#include "bindings.h"
#include "spline_arrays.h"
#include "trivox/inverse/invert.h"

namespace trivox::python {

namespace {

// Named tuples of the inverse maps' results (created at import; collections needs no numpy).
py::object g_inversion_type, g_global_inversion_type;

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

py::object volume_invert(const PyVolume& self, const py::handle& points, const py::handle& hint, bool certified,
                         double residual_tolerance_model, int max_iterations, double outside_slack_relative,
                         int threads) {
  GlobalSolveParams global;
  global.newton = inverse_params(residual_tolerance_model, max_iterations, outside_slack_relative);
  const InverseParams& params = global.newton;
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
    // Built once (and kept with the volume) before the workers share it.
    const GlobalSolver* solver = certified ? &self.solver() : nullptr;
    for_chunks(xs.size(), threads, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Vec3 h = hs ? hs[i] : one_hint;
        const InverseResult res =
            solver ? invert_certified(self.volume, *solver, xs[i], h, global) : invert(self.volume, xs[i], h, params);
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

void bind_volume_inverse(py::module_& m, VolumeClass& volume) {
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
  volume
      .def("invert", &volume_invert, py::arg("points"), py::arg("hint") = py::none(), py::kw_only(),
           py::arg("certified") = true, py::arg("residual_tolerance_model") = InverseParams{}.residual_tolerance_model,
           py::arg("max_iterations") = InverseParams{}.max_iterations,
           py::arg("outside_slack_relative") = InverseParams{}.outside_slack_relative, py::arg("threads") = 0,
           R"doc(
The parameters (u, v, w) of every point: points (..., 3) in model units; hint None (the
domain's centre), one (u, v, w), or one per point. Certified by default
(trivox::invert_certified): damped Newton from the hint, and where it does not converge the
global solver, which finds the preimage (the one nearest the hint) or proves the point
outside. certified=False runs Newton alone (trivox::invert), faster where every point is
known to be near its hint, and may then leave points inside unsolved. Returns
Inversion(uvw, status, residual, iterations); status holds InverseStatus codes (CONVERGED,
OUTSIDE, NO_CONVERGENCE, SINGULAR; .statuses gives them as InverseStatus members, which print
by name). The other keyword arguments are InverseParams with their C++ defaults;
invert_global finds every preimage.
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
)doc");
}

}  // namespace trivox::python
