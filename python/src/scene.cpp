// Scenes (scene/scene.h) as seen from Python, and the one material kind Python adds: a
// Python callable evaluated over whole rows of samples.
//
// A scene is always read by the library's scene reader (from a file, or from the JSON text
// that trivox.Scene composes from Python objects), so every rule and message of the scene
// file holds for scenes built in Python too. A cell whose material is a Python callable is
// read with the material "void" in its place, and the callable then takes its place, wrapped
// in the scene's fraction policy like every other material (CheckedMaterial).
#include <Python.h>

#include <algorithm>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/material/checked_material.h"

namespace trivox::python {

namespace {

// M(u, v, w) from a Python callable f(u, v, w, x, y, z): u, v, w are the cell's parameters
// normalised to [0, 1] (as for the expression kind, clamped), x, y, z the positions in mm,
// each a float64 array of the row's n samples. f returns the fractions as an (n, m) array,
// or a sequence of m arrays of n values (or numbers, the same for every sample); for one
// material an (n,) array too. The GIL is taken once per row, never per sample.
class PythonMaterial final : public MaterialFunction {
 public:
  PythonMaterial(py::object fn, int num_materials, const ParamBox& cell_domain, std::string cell)
      : MaterialFunction(num_materials),
        fn_(std::move(fn)),
        map_(AffineParamMap::between(cell_domain, kUnitParamBox)),
        cell_(std::move(cell)) {}

  ~PythonMaterial() override {
    // The last reference to the callable may go on a thread without the GIL; after the
    // interpreter has ended it must not be touched at all.
    if (Py_IsInitialized() != 0) {
      py::gil_scoped_acquire gil;
      fn_ = py::object();
    } else {
      fn_.release();
    }
  }

  std::string_view kind() const noexcept override { return "python"; }

  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override {
    const std::size_t n = uvw.size();
    if (n == 0) return;
    const auto m = static_cast<std::size_t>(num_materials());
    py::gil_scoped_acquire gil;
    const auto count = static_cast<py::ssize_t>(n);
    py::array_t<double> u(count), v(count), w(count), x(count), y(count), z(count);
    double *pu = u.mutable_data(), *pv = v.mutable_data(), *pw = w.mutable_data();
    double *px = x.mutable_data(), *py_ = y.mutable_data(), *pz = z.mutable_data();
    for (std::size_t s = 0; s < n; ++s) {
      const Vec3 p = kUnitParamBox.clamp(map_(uvw[s]));
      pu[s] = p.x;
      pv[s] = p.y;
      pw[s] = p.z;
      px[s] = xyz[s].x;
      py_[s] = xyz[s].y;
      pz[s] = xyz[s].z;
    }
    const py::object result = fn_(u, v, w, x, y, z);
    auto fail = [&](const std::string& what) {
      throw py::value_error("the Python material of cell '" + cell_ + "' " + what + "; it must return the " +
                            std::to_string(m) + " fractions of the " + std::to_string(n) +
                            " samples as an array of shape (n, m) or a sequence of m arrays of shape (n,) or numbers");
    };
    if (py::isinstance<py::tuple>(result) || py::isinstance<py::list>(result)) {
      const py::sequence seq = py::reinterpret_borrow<py::sequence>(result);
      if (static_cast<std::size_t>(seq.size()) != m)
        fail("returned a sequence of " + std::to_string(seq.size()) + " items");
      for (std::size_t j = 0; j < m; ++j) {
        const DoubleArray a = DoubleArray::ensure(seq[j]);
        if (!a) {
          PyErr_Clear();
          fail("returned an item that is not numbers (item " + std::to_string(j) + ")");
        }
        if (a.ndim() == 0) {
          const auto value = static_cast<float>(*a.data());
          for (std::size_t s = 0; s < n; ++s) fractions[s * m + j] = value;
        } else if (a.ndim() == 1 && static_cast<std::size_t>(a.shape(0)) == n) {
          const double* src = a.data();
          for (std::size_t s = 0; s < n; ++s) fractions[s * m + j] = static_cast<float>(src[s]);
        } else {
          fail("returned item " + std::to_string(j) + " with " + std::to_string(a.size()) + " values");
        }
      }
      return;
    }
    const DoubleArray a = DoubleArray::ensure(result);
    if (!a) {
      PyErr_Clear();
      fail("returned something that is not an array of numbers");
    }
    const bool matrix =
        a.ndim() == 2 && static_cast<std::size_t>(a.shape(0)) == n && static_cast<std::size_t>(a.shape(1)) == m;
    const bool column = a.ndim() == 1 && m == 1 && static_cast<std::size_t>(a.shape(0)) == n;
    if (!matrix && !column) {
      std::string shape = "(";
      for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
      fail("returned an array of shape " + shape + (a.ndim() == 1 ? ",)" : ")"));
    }
    const double* src = a.data();
    for (std::size_t k = 0; k < n * m; ++k) fractions[k] = static_cast<float>(src[k]);
  }

 private:
  py::object fn_;
  AffineParamMap map_;
  std::string cell_;
};

py::dict cell_dict(const Scene& scene, const Cell& c) {
  py::dict d;
  d["name"] = c.name;
  d["pointer"] = c.pointer;
  auto v = std::make_shared<PyVolume>(c.volume);
  d["volume"] = v;
  const auto* checked = dynamic_cast<const CheckedMaterial*>(c.material.get());
  d["material"] = std::string(checked ? checked->inner().kind() : c.material->kind());
  d["material_pointer"] = checked ? checked->site().pointer : std::string();
  d["scene_volume"] = c.scene_volume >= 0
                          ? py::object(py::str(scene.volumes[static_cast<std::size_t>(c.scene_volume)].name))
                          : py::none();
  py::list trim;
  for (const TrimClause& k : c.trim.clauses) {
    py::dict t;
    t["kind"] = std::string(to_string(k.kind));
    t["side"] = std::string(to_string(k.side));
    if (k.kind == TrimKind::kVolume)
      t["volume"] = scene.volumes[static_cast<std::size_t>(k.volume)].name;
    else if (k.shell)
      t["shell"] = k.shell->name;
    trim.append(t);
  }
  d["trim"] = trim;
  return d;
}

// The scene with each (material pointer, callable) pair's cells given the callable.
ScenePtr with_python_materials(const ScenePtr& scene, const std::vector<std::pair<std::string, py::object>>& pairs) {
  auto copy = std::make_shared<Scene>(*scene);
  for (const auto& [pointer, fn] : pairs) {
    if (!PyCallable_Check(fn.ptr())) throw py::type_error("the Python material at " + pointer + " is not callable");
    bool found = false;
    for (Cell& c : copy->cells) {
      const auto* checked = dynamic_cast<const CheckedMaterial*>(c.material.get());
      if (checked == nullptr || checked->site().pointer != pointer) continue;
      auto raw = std::make_shared<PythonMaterial>(fn, copy->num_materials(), c.volume.domain(), c.name);
      c.material = std::make_shared<CheckedMaterial>(std::move(raw), copy->fraction_policy, checked->site());
      found = true;
    }
    if (!found) throw py::value_error("no cell of the scene has its material at " + pointer);
  }
  return copy;
}

py::array_t<float> evaluate_material(const ScenePtr& scene, int cell, const py::handle& params) {
  if (cell < 0 || static_cast<std::size_t>(cell) >= scene->cells.size())
    throw py::index_error("cell index " + std::to_string(cell) + " is out of range (the scene has " +
                          std::to_string(scene->cells.size()) + " cells)");
  const Cell& c = scene->cells[static_cast<std::size_t>(cell)];
  const Vec3Batch in = vec3_batch(params, "params");
  const auto m = static_cast<std::size_t>(scene->num_materials());
  std::vector<py::ssize_t> shape = in.lead;
  shape.push_back(static_cast<py::ssize_t>(m));
  py::array_t<float> out(shape);
  const std::span<const Vec3> uvw = in.points();
  float* f = out.mutable_data();
  {
    py::gil_scoped_release release;
    std::vector<Vec3> xyz(uvw.size());
    c.volume.evaluate_many(uvw, xyz);
    c.material->evaluate_row(uvw, xyz, std::span<float>(f, uvw.size() * m));
  }
  return out;
}

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<SceneHandle>(m, "SceneHandle",
                          "A scene as the library read it (trivox::Scene); trivox.Scene holds one. Not made directly.")
      .def_property_readonly("source", [](const SceneHandle& h) { return h.scene->source; })
      .def_property_readonly("source_sha256", [](const SceneHandle& h) { return h.scene->source_sha256; })
      .def_property_readonly("input_files",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               py::list out;
                               for (const SceneInputFile& f : s->input_files)
                                 out.append(py::make_tuple(f.name, f.sha256));
                               return out;
                             })
      .def_property_readonly("printer",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               py::dict d;
                               d["name"] = s->printer.name;
                               d["x_dpi"] = s->printer.x_dpi;
                               d["y_dpi"] = s->printer.y_dpi;
                               d["layer_thickness_mm"] = s->printer.layer_thickness_mm;
                               d["max_materials"] = s->printer.max_materials;
                               return d;
                             })
      .def_property_readonly("materials",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               py::list out;
                               for (const MaterialDef& md : s->materials) {
                                 py::dict d;
                                 d["name"] = md.name;
                                 d["rgba"] = py::make_tuple(md.rgba[0], md.rgba[1], md.rgba[2], md.rgba[3]);
                                 d["library"] = md.library;
                                 out.append(d);
                               }
                               return out;
                             })
      .def_property_readonly("volumes",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               py::list out;
                               for (const SceneVolume& v : s->volumes) {
                                 py::dict d;
                                 d["name"] = v.name;
                                 d["pointer"] = v.pointer;
                                 d["volume"] = std::make_shared<PyVolume>(v.volume);
                                 out.append(d);
                               }
                               return out;
                             })
      .def_property_readonly("cells",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               py::list out;
                               for (const Cell& c : s->cells) out.append(cell_dict(*s, c));
                               return out;
                             })
      .def_property_readonly("bounds",
                             [](const SceneHandle& h) {
                               const Scene* s = h.scene.get();
                               const Box3 b = s->bounds();
                               py::array_t<double> a({py::ssize_t{2}, py::ssize_t{3}});
                               for (int k = 0; k < 3; ++k) {
                                 a.mutable_at(0, k) = b.lo[k];
                                 a.mutable_at(1, k) = b.hi[k];
                               }
                               return a;
                             })
      .def(
          "with_python_materials",
          [](const SceneHandle& h, const std::vector<std::pair<std::string, py::object>>& pairs) {
            return SceneHandle{with_python_materials(h.scene, pairs)};
          },
          py::arg("pairs"))
      .def(
          "evaluate_material",
          [](const SceneHandle& h, int cell, const py::handle& params) {
            return evaluate_material(h.scene, cell, params);
          },
          py::arg("cell"), py::arg("params"));

  m.def(
      "_read_scene",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return SceneHandle{std::make_shared<Scene>(read_scene(path))};
      },
      py::arg("path"));
  m.def(
      "_parse_scene",
      [](const std::string& text, const std::filesystem::path& source) {
        py::gil_scoped_release release;
        return SceneHandle{std::make_shared<Scene>(parse_scene(text, source))};
      },
      py::arg("text"), py::arg("source"));
}

}  // namespace trivox::python
