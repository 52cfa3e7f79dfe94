// The library's exceptions as Python exceptions, one class per C++ class (error.h), carrying
// the same message the command line prints after "trivox: error: ". InputError keeps its
// parts as attributes (file, line, where, rule).
#include <Python.h>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/material/expression_material.h"

namespace trivox::python {

namespace {

// The classes live as long as the interpreter (the module holds a reference too).
PyObject* g_error = nullptr;
PyObject* g_model_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_unsupported_error = nullptr;
PyObject* g_io_error = nullptr;
PyObject* g_expression_error = nullptr;
PyObject* g_empty_result_error = nullptr;

PyObject* new_class(py::module_& m, const char* name, const char* doc, PyObject* base) {
  const std::string qualified = std::string("trivox.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.add_object(name, py::reinterpret_borrow<py::object>(type));
  return type;
}

// Raises an instance of `type` with the message and the attributes.
void raise(PyObject* type, const char* message, const py::dict& attributes) {
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  for (const auto& [key, value] : attributes) exc.attr(key) = value;
  PyErr_SetObject(type, exc.ptr());
}

void raise_input(PyObject* type, const InputError& e) {
  py::dict a;
  a["file"] = e.file();
  a["line"] = e.line();
  a["where"] = e.where();
  a["rule"] = e.rule();
  raise(type, e.what(), a);
}

}  // namespace

void bind_errors(py::module_& m) {
  g_error = new_class(m, "Error",
                      "Base of every error the trivox library raises on purpose (bad input, a file that cannot be "
                      "read or written, settings a job cannot take).",
                      PyExc_RuntimeError);
  g_model_error = new_class(m, "ModelError",
                            "A spline or model that breaks a structural rule (decreasing knots, a weight <= 0, counts "
                            "that disagree).",
                            g_error);
  g_input_error = new_class(m, "InputError",
                            "Bad content read from a file: str(e) is 'file:line: where: rule' (for scenes 'scene.json: "
                            "/json/pointer: rule'); the parts are e.file, e.line, e.where, e.rule.",
                            g_error);
  g_unsupported_error =
      new_class(m, "UnsupportedError",
                "A valid file that uses something trivox does not handle (e.g. hierarchical splines).", g_input_error);
  g_io_error = new_class(m, "IoError", "A file or folder that cannot be read or written.", g_error);
  g_expression_error = new_class(m, "ExpressionError",
                                 "An expression that does not compile; e.index is the material index of the expression "
                                 "(-1 for a constant's name).",
                                 g_error);
  g_empty_result_error =
      new_class(m, "EmptyResultError",
                "A job that sliced every layer of the object itself made a stack without a voxel of it (the object "
                "is thinner than a pixel, or falls between pixel centres); the files are complete. slice(..., "
                "allow_empty=True) accepts such a stack.",
                g_error);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const UnsupportedError& e) {
      raise_input(g_unsupported_error, e);
    } catch (const InputError& e) {
      raise_input(g_input_error, e);
    } catch (const ExpressionError& e) {
      py::dict a;
      a["index"] = e.index();
      raise(g_expression_error, e.what(), a);
    } catch (const ModelError& e) {
      PyErr_SetString(g_model_error, e.what());
    } catch (const IoError& e) {
      PyErr_SetString(g_io_error, e.what());
    } catch (const EmptyResultError& e) {
      PyErr_SetString(g_empty_result_error, e.what());
    } catch (const Error& e) {
      PyErr_SetString(g_error, e.what());
    }
  });
}

}  // namespace trivox::python
