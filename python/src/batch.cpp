// What the bindings share for batches of points: arrays of 3-vectors, new output arrays, the
// chunks a bulk call shares among workers, directions by name, and the spline of a Volume or a
// Spline (bindings.h).
#include <algorithm>
#include <string>

#include "bindings.h"
#include "trivox/parallel.h"

namespace trivox::python {

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

// The Spline of a Volume or a Spline (the constructors and refinements take either).
const TensorSpline& spline_of(const py::handle& obj) {
  if (py::isinstance<PyVolume>(obj)) return py::cast<const PyVolume&>(obj).volume.spline();
  return py::cast<const TensorSpline&>(obj);
}

}  // namespace trivox::python
