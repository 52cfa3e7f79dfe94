// Model files (io/model.h), PNG images (output/png_io.h) and the printer tables (printer/):
// trivox.read, trivox.to_itd, trivox.read_png, trivox.write_png, the material library and
// the built-in printer profiles.
#include <filesystem>
#include <sstream>

#include "bindings.h"
#include "trivox/io/model.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"
#include "trivox/printer/material_library.h"
#include "trivox/printer/printer_profile.h"

namespace trivox::python {

namespace {

// The model's trivariates with 3D points as Volumes that remember their file and index.
py::list model_volumes(const Model& model) {
  py::list out;
  std::string file;
  if (!model.source.empty()) {
    std::error_code ec;
    const auto abs = std::filesystem::absolute(model.source, ec);
    file = ec ? model.source : abs.lexically_normal().string();
  }
  const std::vector<int> indices = model.volume_indices();
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const TensorSpline& s = model.patches[static_cast<std::size_t>(indices[k])].spline;
    if (s.point_dim() != 3) continue;
    auto v = std::make_shared<PyVolume>(Volume(s));
    v->source_file = file;
    v->source_patch = static_cast<int>(k);
    out.append(v);
  }
  return out;
}

// A Model from what Python gives: a Model, or a list of Patch, Spline or Volume objects.
Model as_model(const py::handle& obj) {
  if (py::isinstance<Model>(obj)) return py::cast<Model>(obj);
  Model m;
  int index = 0;
  for (const py::handle item : obj) {
    if (py::isinstance<Patch>(item)) {
      m.patches.push_back(py::cast<Patch>(item));
    } else {
      Patch p{"", index, 0, spline_of(item)};
      p.name = "PATCH" + std::to_string(index);
      m.patches.push_back(std::move(p));
    }
    ++index;
  }
  return m;
}

py::array_t<std::uint8_t> rgba_array(RgbaImage&& image) {
  auto* owned = new RgbaImage(std::move(image));
  py::capsule owner(owned, [](void* p) { delete static_cast<RgbaImage*>(p); });
  return py::array_t<std::uint8_t>({owned->height_px, owned->width_px, 4}, owned->rgba.data(), owner);
}

py::dict profile_dict(const PrinterProfile& p) {
  py::dict d;
  d["name"] = p.name;
  d["x_dpi"] = p.x_dpi;
  d["y_dpi"] = p.y_dpi;
  d["layer_thickness_mm"] = p.layer_thickness_mm;
  d["max_materials"] = p.max_materials;
  return d;
}

// A model's text in one of the formats the library writes (to_itd, to_g2, to_gismo_xml).
std::string model_text(const py::handle& items, ModelFormat format) {
  std::ostringstream out;
  write_model(out, as_model(items), format);
  return out.str();
}

// (name, family, (r, g, b, a)) of a library material.
py::tuple library_material_tuple(const LibraryMaterial& lm) {
  return py::make_tuple(std::string(lm.name), std::string(lm.family),
                        py::make_tuple(lm.rgba[0], lm.rgba[1], lm.rgba[2], lm.rgba[3]));
}

// Model files: Patch, Model, reading and writing them.
void bind_model_files(py::module_& m) {
  py::class_<Patch>(m, "Patch", "One spline of a model file: its name, id, the line it starts on, and the spline.")
      .def_readonly("name", &Patch::name, "The object's name (IRIT) or 'Geometry id=N' (G+Smo).")
      .def_readonly("id", &Patch::id, "G+Smo's id attribute, or the patch's index.")
      .def_readonly("source_line", &Patch::source_line, "Line where the patch starts (1-based; 0 when unknown).")
      .def_readonly("spline", &Patch::spline, "The spline (curve, surface or trivariate).")
      .def("__repr__", [](const Patch& p) {
        return "<trivox.Patch '" + p.name + "' line " + std::to_string(p.source_line) + ", " +
               std::to_string(p.spline.param_dim()) + " parameters, point dimension " +
               std::to_string(p.spline.point_dim()) + ">";
      });

  py::class_<Model>(m, "Model",
                    "A model file's splines in document order (trivox::Model); volumes() gives its trivariates.")
      .def_readonly("source", &Model::source, "The file it was read from (as given).")
      .def_readonly("patches", &Model::patches, "Every spline of the file, in document order.")
      .def_property_readonly(
          "trimmed_models",
          [](const Model& md) {
            py::list out;
            for (const TrimmedModel& t : md.trimmed_models) {
              py::dict d;
              d["name"] = t.name;
              d["source_line"] = t.source_line;
              d["surfaces"] = t.surfaces.size();
              d["segments"] = t.segments.size();
              out.append(d);
            }
            return out;
          },
          "IRIT MODEL objects (trimmed surfaces): name, source_line and their counts of surfaces and segments.")
      .def("volumes", &model_volumes,
           "The trivariates with 3D points as Volume objects, in document order; each remembers its file and index "
           "(Volume.source), so a scene refers to the file rather than copying it.")
      .def("__len__", [](const Model& md) { return md.patches.size(); })
      .def("__repr__", [](const Model& md) {
        return "<trivox.Model '" + md.source + "': " + std::to_string(md.patches.size()) + " patches, " +
               std::to_string(md.volume_indices().size()) + " trivariates>";
      });

  m.def(
      "read",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return read_model(path);
      },
      py::arg("path"),
      "Reads a model file by its type: IRIT .itd, G+Smo .xml or GoTools .g2 (trivox::read_model). Raises InputError "
      "(file, "
      "line, rule) for malformed content, UnsupportedError for valid but unsupported content, IoError when the "
      "file cannot be read.");
  m.def(
      "read_itd", [](std::string_view text, const std::string& source) { return read_itd(text, source); },
      py::arg("text"), py::arg("source") = "<string>", "Parses IRIT .itd text.");
  m.def(
      "read_gismo_xml", [](std::string_view text, const std::string& source) { return read_gismo_xml(text, source); },
      py::arg("text"), py::arg("source") = "<string>", "Parses G+Smo XML text.");
  m.def(
      "to_itd", [](const py::handle& items) { return model_text(items, ModelFormat::kItd); }, py::arg("model"),
      "IRIT .itd text of a Model or a list of Spline, Volume or Patch objects (17 significant digits: knots, "
      "weights and the points of polynomial patches read back to the same doubles; a rational point is stored "
      "as w * x and may read back an ulp away, docs/FORMATS.md).");
  m.def(
      "read_g2", [](std::string_view text, const std::string& source) { return read_g2(text, source); },
      py::arg("text"), py::arg("source") = "<string>", "Parses GoTools .g2 text.");
  m.def(
      "to_g2", [](const py::handle& items) { return model_text(items, ModelFormat::kG2); }, py::arg("model"),
      "GoTools .g2 text of a Model or a list of Spline, Volume or Patch objects (SplineCurve, SplineSurface, "
      "SplineVolume; 17 significant digits: knots, weights and the points of polynomial patches read back to "
      "the same doubles; a rational point is stored homogeneous, chosen to divide back to the same double where "
      "one does, else within an ulp, docs/FORMATS.md).");
  m.def(
      "to_gismo_xml", [](const py::handle& items) { return model_text(items, ModelFormat::kGismoXml); },
      py::arg("model"),
      "G+Smo XML text of a Model or a list of Spline, Volume or Patch objects: a <Geometry> per patch and, when "
      "all have the same number of parameters, a <MultiPatch> with the interfaces found from shared faces; "
      "read_gismo_xml gives the same doubles back.");
}

// PNG images, the material library, the printer profiles and the output formats.
void bind_images_and_printers(py::module_& m) {
  m.def(
      "read_png",
      [](const std::filesystem::path& path) {
        RgbaImage image;
        {
          py::gil_scoped_release release;
          image = read_png_rgba(path);
        }
        return rgba_array(std::move(image));
      },
      py::arg("path"), "Any PNG as 8-bit RGBA, an array (height, width, 4) uint8 (row 0 at the top).");
  m.def(
      "write_png",
      [](const std::filesystem::path& path, const py::array_t<std::uint8_t, py::array::c_style>& pixels,
         int zlib_level) {
        PngWriteParams params;
        params.zlib_level = zlib_level;
        params.validate();
        if (pixels.ndim() == 3 && pixels.shape(2) == 4) {
          const std::span<const std::uint8_t> px(pixels.data(), static_cast<std::size_t>(pixels.size()));
          py::gil_scoped_release release;
          write_png_rgba(path, static_cast<int>(pixels.shape(1)), static_cast<int>(pixels.shape(0)), px, params);
        } else if (pixels.ndim() == 2) {
          const std::span<const std::uint8_t> px(pixels.data(), static_cast<std::size_t>(pixels.size()));
          py::gil_scoped_release release;
          write_png_gray8(path, static_cast<int>(pixels.shape(1)), static_cast<int>(pixels.shape(0)), px, params);
        } else {
          throw py::value_error("pixels: expected (height, width, 4) RGBA or (height, width) gray, uint8");
        }
      },
      py::arg("path"), py::arg("pixels"), py::arg("zlib_level") = PngWriteParams{}.zlib_level,
      "Writes (height, width, 4) uint8 as an RGBA PNG, or (height, width) as 8-bit gray, atomically.");

  m.def(
      "material_library",
      [] {
        py::list out;
        for (const LibraryMaterial& lm : material_library()) out.append(library_material_tuple(lm));
        return out;
      },
      "The named J750/J850 materials a scene may use without a colour: (name, family, (r, g, b, a)) each; the "
      "colours are display approximations.");
  m.def(
      "find_library_material",
      [](const std::string& name) -> py::object {
        const auto lm = find_library_material(name);
        if (!lm) return py::none();
        return library_material_tuple(*lm);
      },
      py::arg("name"), "The library material called name (ignoring case, spaces, '-' and '_'), or None.");
  m.def(
      "printer_profile", [](const std::string& name) { return profile_dict(builtin_printer_profile(name)); },
      py::arg("name"), "A built-in printer profile as a dict (name, x_dpi, y_dpi, layer_thickness_mm, max_materials).");
  m.def("printer_profile_names", &builtin_printer_profile_names, "The built-in printer profiles' names.");
  m.def("formats", &layer_writer_names,
        "The output formats of a slicing job: voxelprint, bitmaps, legacy, tiff, vdb, gcvf, preview.");
}

}  // namespace

void bind_model(py::module_& m) {
  bind_model_files(m);
  bind_images_and_printers(m);
}

}  // namespace trivox::python
