// The compiled part of the `trivox` Python package, `trivox._trivox` (docs/PYTHON.md). The
// package's __init__.py re-exports it with the pure-Python scene and material builders.
// Importing it needs no numpy: numpy is loaded on the first call that takes or returns an
// array.
#include <string>

#include "bindings.h"
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
}
