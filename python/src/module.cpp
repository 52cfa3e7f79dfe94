// The compiled part of the `trivox` Python package, `trivox._trivox` (docs/PYTHON.md). The
// package's __init__.py re-exports it with the pure-Python scene and material builders.
// Importing it needs no numpy: numpy is loaded on the first call that takes or returns an
// array.
#include <string>

#include "bindings.h"
#include "trivox/simd.h"
#include "trivox/version.h"

PYBIND11_MODULE(_trivox, m) {
  namespace tp = trivox::python;
  m.doc() = "trivox's C++ library, bound with pybind11 (use the `trivox` package, which re-exports it).";
  m.attr("__version__") = std::string(trivox::version());
  tp::bind_errors(m);
  tp::bind_spline(m);
  tp::bind_model(m);
  tp::bind_construct(m);
  tp::bind_scene(m);
  tp::bind_slice(m);
  tp::bind_job(m);
  // The evaluation kernels' SIMD targets (docs/PYTHON.md, "Evaluation and inversion").
  m.def("simd_targets", &trivox::simd_targets,
        "The SIMD targets this processor runs in this build, best first (e.g. ['avx512', 'avx2', 'sse4', "
        "'baseline']).");
  m.def("simd_target", &trivox::simd_target, "The SIMD target the evaluation kernels run on now.");
  m.def(
      "use_simd_target", [](const std::string& name) { trivox::use_simd_target(name); }, pybind11::arg("name"),
      "Restricts the kernels to one of simd_targets() ('best' lifts it); volumes built afterwards use it. "
      "Raises InputError for a name this processor cannot run.");
}
