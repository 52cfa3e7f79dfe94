// Slicing (slice/): one layer to numpy arrays, the layout and the dithering of a slicer
// (docs/PYTHON.md, "Slicing"); the whole job is job.cpp's.
#include <string_view>

#include "bindings.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/slice/slicer.h"

namespace trivox::python {

namespace {

// A zero-copy array over a value moved to the heap, freed with the array.
template <class T, class Owner, class DataOf>
py::array_t<T> owned_array(Owner&& value, DataOf data_of, std::vector<py::ssize_t> shape) {
  auto* held = new Owner(std::move(value));
  py::capsule owner(held, [](void* p) { delete static_cast<Owner*>(p); });
  return py::array_t<T>(shape, data_of(*held), owner);
}

std::unique_ptr<PySlicer> make_slicer(const SceneHandle& handle, const std::string& tracing,
                                      double residual_tolerance_mm, std::optional<double> outline_tolerance_mm,
                                      const std::optional<std::string>& dither, std::optional<int> skin,
                                      std::optional<bool> vary_by_layer) {
  // The settings of `trivox slice` (apps/trivox/job_options.cpp): the scene's dithering with
  // the options given here on top.
  SliceParams params;
  const auto strategy = parse_tracing_strategy(tracing);
  if (!strategy)
    throw py::value_error("tracing must be none, previous-point, previous-line, full, predict or flood, got '" +
                          tracing + "'");
  params.tracing = *strategy;
  params.newton.residual_tolerance_model = residual_tolerance_mm;
  params.outline_tolerance_mm = outline_tolerance_mm;
  DitherParams d = handle.scene->dithering.value_or(DitherParams{});
  if (dither && !set_dither_method(*dither, d)) {
    std::string names;
    for (std::string_view n : dither_method_names()) names += (names.empty() ? "" : ", ") + std::string(n);
    throw py::value_error("dither must be one of " + names + ", got '" + *dither + "'");
  }
  if (skin) d.skin_voxels = *skin;
  if (vary_by_layer) d.vary_by_layer = *vary_by_layer;
  params.dither = d;
  auto s = std::make_unique<PySlicer>();
  params.stop = &s->stop;
  s->scene = handle.scene;
  {
    py::gil_scoped_release release;
    s->slicer = std::make_unique<Slicer>(*s->scene, params);
  }
  return s;
}

py::dict slice_one(const PySlicer& s, int layer, bool fractions, bool owner) {
  const SliceLayout& L = s.slicer->layout();
  if (layer < 0 || layer >= L.num_layers)
    throw py::index_error("layer " + std::to_string(layer) + " is out of range: the scene has " +
                          std::to_string(L.num_layers) + " layers (0 to " + std::to_string(L.num_layers - 1) + ")");
  LayerResult r;
  s.stop = false;
  {
    py::gil_scoped_release release;
    r = s.slicer->slice_layer(layer, {.owner = owner, .rasters = fractions});
  }
  const py::ssize_t h = L.height_px, w = L.width_px;
  py::dict out;
  auto values_of = [](const auto& raster) { return raster.values().data(); };
  out["labels"] = owned_array<std::uint8_t>(std::move(r.labels), values_of, {h, w});
  out["stats"] = stats_dict(r.stats);
  if (fractions) {
    const py::ssize_t m = r.rasters.fractions.num_materials();
    out["fractions"] = owned_array<float>(std::move(r.rasters.fractions), values_of, {h, w, m});
    out["inside"] = owned_array<std::uint8_t>(std::move(r.rasters.inside), values_of, {h, w});
  }
  if (owner) {
    out["owner"] = owned_array<int>(std::move(r.owner), [](const std::vector<int>& v) { return v.data(); }, {h, w});
  }
  return out;
}

}  // namespace

py::dict stats_dict(const LayerStats& s, LayerStatsPart part) {
  py::dict d;
  visit_layer_stats(s, part,
                    [&d](std::string_view name, const auto& value) { d[py::str(name.data(), name.size())] = value; });
  return d;
}

void bind_slice(py::module_& m) {
  py::class_<SliceLayout>(m, "Layout",
                          "Where each layer and pixel of a job lies in model space (mm): pixel (col, row) samples "
                          "x = x0_mm + (col + 0.5) pitch_x_mm, y = y_top_mm - (row + 0.5) pitch_y_mm (row 0 on "
                          "top); layer l samples z = z0_mm + (l + 0.5) layer_mm.")
      .def_readonly("x0_mm", &SliceLayout::x0_mm, "The left edge of column 0 (mm).")
      .def_readonly("y_top_mm", &SliceLayout::y_top_mm, "The top edge of row 0 (mm).")
      .def_readonly("z0_mm", &SliceLayout::z0_mm, "The bottom of layer 0 (mm).")
      .def_readonly("pitch_x_mm", &SliceLayout::pitch_x_mm, "Pixel pitch along x, the image width (mm).")
      .def_readonly("pitch_y_mm", &SliceLayout::pitch_y_mm, "Pixel pitch along y, the image height (mm).")
      .def_readonly("layer_mm", &SliceLayout::layer_mm, "Layer thickness (mm).")
      .def_readonly("width_px", &SliceLayout::width_px, "Pixels per row (the images' width).")
      .def_readonly("height_px", &SliceLayout::height_px, "Rows (the images' height).")
      .def_readonly("num_layers", &SliceLayout::num_layers, "Layers of the model.")
      .def("x_of_col", &SliceLayout::x_of_col, py::arg("col"), "x (mm) of the centre of column col.")
      .def("y_of_row", &SliceLayout::y_of_row, py::arg("row"), "y (mm) of the centre of row row.")
      .def("z_of_layer", &SliceLayout::z_of_layer, py::arg("layer"), "z (mm) of the middle of layer layer.")
      .def("__repr__", [](const SliceLayout& L) {
        return "<trivox.Layout " + std::to_string(L.num_layers) + " layers of " + std::to_string(L.width_px) + " x " +
               std::to_string(L.height_px) + " px>";
      });

  py::class_<PySlicer>(m, "_Slicer")
      .def(py::init(&make_slicer), py::arg("scene"), py::arg("tracing"), py::arg("residual_tolerance_mm"),
           py::arg("outline_tolerance_mm"), py::arg("dither"), py::arg("skin"), py::arg("vary_by_layer"))
      .def_property_readonly("layout", [](const PySlicer& s) { return s.slicer->layout(); })
      .def_property_readonly(
          "background",
          [](const PySlicer& s) {
            const auto c = job_background(s.slicer->scene(), JobParams{});
            return py::make_tuple(c[0], c[1], c[2], c[3]);
          },
          "The job's automatic background colour (r, g, b, 255): black, or white or a grey when a material "
          "takes black (trivox::job_background).")
      .def_property_readonly("dithering",
                             [](const PySlicer& s) {
                               const DitherParams& d = s.slicer->dither_params();
                               py::dict out;
                               out["method"] = std::string(dither_method_name(d));
                               out["serpentine"] = d.serpentine;
                               out["vary_by_layer"] = d.vary_by_layer;
                               out["skin_voxels"] = d.skin_voxels;
                               return out;
                             })
      .def("slice_layer", &slice_one, py::arg("layer"), py::arg("fractions") = false, py::arg("owner") = false);
  // The names of a layer's stats (stats.json's, in visit_layer_stats' order), so that a test
  // can hold the Python dicts to the library's list.
  m.def("_layer_stats_names", [] {
    std::vector<std::string> names;
    visit_layer_stats(LayerStats{}, LayerStatsPart::kLayer,
                      [&names](std::string_view name, const auto&) { names.emplace_back(name); });
    return names;
  });
}

}  // namespace trivox::python
