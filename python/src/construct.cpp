// Volume constructors (construct/): the functions behind the scene file's "extrude",
// "ruled", "revolve", "sweep", "coons" and "shell", with the same inputs and defaults, each
// returning Constructed(volume, report).
#include <array>
#include <map>
#include <optional>

#include "bindings.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/extrude.h"
#include "trivox/construct/join.h"
#include "trivox/construct/report.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/shell.h"
#include "trivox/construct/sweep.h"
#include "trivox/construct/untangle.h"

namespace trivox::python {

namespace {

py::object g_constructed_type;

JacobianCheckParams check_params(int jacobian_samples) {
  if (jacobian_samples < 2 || jacobian_samples > 65) throw py::value_error("jacobian_samples must be 2 to 65");
  JacobianCheckParams p;
  p.samples_per_direction = jacobian_samples;
  return p;
}

py::object constructed(Constructed&& c) {
  auto v = std::make_shared<PyVolume>(std::move(c.volume));
  return g_constructed_type(v, std::move(c.report));
}

// Runs a constructor without the GIL (the sweep and the untangling take a while).
template <class F>
py::object build(F&& f) {
  std::optional<Constructed> c;
  {
    py::gil_scoped_release release;
    c.emplace(f());
  }
  return constructed(std::move(*c));
}

py::tuple box_tuple(const ParamBox& b) {
  return py::make_tuple(py::make_tuple(b.lo.x, b.lo.y, b.lo.z), py::make_tuple(b.hi.x, b.hi.y, b.hi.z));
}

// (samples, (lo, hi) parameter box) of a region of the Jacobian check, or None when empty.
py::object region_or_none(const JacobianRegion& region) {
  if (region.samples == 0) return py::none();
  return py::make_tuple(region.samples, box_tuple(region.box));
}

UntangleParams untangle_params(const py::dict& d) {
  UntangleParams p;
  for (const auto& [key, value] : d) {
    const std::string k = py::cast<std::string>(key);
    if (k == "knots_per_span")
      p.knots_per_span = py::cast<int>(value);
    else if (k == "iterations")
      p.iterations = py::cast<int>(value);
    else if (k == "samples_per_span")
      p.samples_per_span = py::cast<int>(value);
    else if (k == "target" || k == "target_relative")
      p.target_relative = py::cast<double>(value);
    else
      throw py::value_error("untangle: unknown key '" + k +
                            "'; the keys are knots_per_span, iterations, samples_per_span, target");
  }
  return p;
}

// ConstructionReport, and the Constructed named tuple of a volume and its report.
void bind_report(py::module_& m) {
  py::class_<ConstructionReport>(m, "ConstructionReport",
                                 "What a constructor reports beside its volume: the sampled Jacobian check and where "
                                 "the volume folds or degenerates, and how close an approximate construction is.")
      .def_readonly("constructor", &ConstructionReport::constructor, "'extrude', 'ruled', 'revolve', ...")
      .def_property_readonly(
          "classification",
          [](const ConstructionReport& r) { return std::string(to_string(r.jacobian.classification)); },
          "'right-handed', 'left-handed', 'degenerate' or 'folded'.")
      .def_property_readonly(
          "samples",
          [](const ConstructionReport& r) {
            py::dict d;
            d["positive"] = r.jacobian.positive;
            d["negative"] = r.jacobian.negative;
            d["zero"] = r.jacobian.zero;
            return d;
          },
          "Counts of samples with det J > 0, < 0 and = 0.")
      .def_property_readonly(
          "det_range",
          [](const ConstructionReport& r) { return py::make_tuple(r.jacobian.min_det, r.jacobian.max_det); },
          "(min, max) of det J over the samples.")
      .def_property_readonly(
          "minority_sign", [](const ConstructionReport& r) { return region_or_none(r.minority_sign); },
          "(samples, (lo, hi) parameter box) where det J has the minority sign, or None.")
      .def_property_readonly(
          "zero", [](const ConstructionReport& r) { return region_or_none(r.zero); },
          "(samples, (lo, hi) parameter box) where det J is zero, or None.")
      .def_readonly("exact", &ConstructionReport::exact, "False for the approximate constructions (sweep, shell).")
      .def_readonly("approximation_error_mm", &ConstructionReport::approximation_error_mm,
                    "For an approximate construction, the largest deviation from the ideal shape found on samples.")
      .def_property_readonly("folds", &ConstructionReport::folds, "True when det J takes both signs.")
      .def("describe", &ConstructionReport::describe, "One line: the classification and where it folds.")
      .def("__repr__", [](const ConstructionReport& r) {
        return "<trivox.ConstructionReport " + r.constructor + ": " + r.describe() + ">";
      });

  py::module_ collections = py::module_::import("collections");
  g_constructed_type =
      collections.attr("namedtuple")("Constructed", py::make_tuple("volume", "report"), py::arg("module") = "trivox");
  g_constructed_type.inc_ref();
  g_constructed_type.attr("__doc__") = "A constructor's result: the Volume and its ConstructionReport.";
  m.attr("Constructed") = g_constructed_type;
}

// The constructors from curves and surfaces: extrude, ruled, revolve, sweep.
void bind_sweeps(py::module_& m) {
  m.def(
      "extrude",
      [](const py::handle& surface, const py::handle& vector_mm, int jacobian_samples) {
        ExtrudeParams p;
        p.vector_mm = to_vec3(vector_mm, "vector_mm");
        p.check = check_params(jacobian_samples);
        const TensorSpline s = spline_of(surface);
        return build([&] { return extrude(s, p); });
      },
      py::arg("surface"), py::arg("vector_mm"), py::kw_only(), py::arg("jacobian_samples") = 9,
      "V(u, v, w) = S(u, v) + w vector_mm, w in [0, 1] (exact). The scene file's 'extrude'.");
  m.def(
      "ruled",
      [](const py::handle& from, const py::handle& to, int jacobian_samples) {
        const TensorSpline a = spline_of(from), b = spline_of(to);
        const RuledParams p{check_params(jacobian_samples)};
        return build([&] { return ruled(a, b, p); });
      },
      py::arg("from_surface"), py::arg("to_surface"), py::kw_only(), py::arg("jacobian_samples") = 9,
      "The volume linear in w between two surfaces (faces w = 0 and w = 1; exact). The scene file's 'ruled'.");
  m.def(
      "revolve",
      [](const py::handle& profile, const py::handle& axis_point_mm, const py::handle& axis_dir, double angle_deg,
         const py::handle& angle_param, int jacobian_samples) {
        RevolveParams p;
        p.axis_point_mm = to_vec3(axis_point_mm, "axis_point_mm");
        p.axis_dir = to_vec3(axis_dir, "axis_dir");
        p.angle_deg = angle_deg;
        if (!(angle_deg > 0.0 && angle_deg <= 360.0)) throw py::value_error("angle_deg must be in (0, 360]");
        p.angle_direction = direction_index(angle_param);
        p.check = check_params(jacobian_samples);
        const TensorSpline s = spline_of(profile);
        return build([&] { return revolve(s, p); });
      },
      py::arg("profile"), py::arg("axis_point_mm") = std::array<double, 3>{0, 0, 0},
      py::arg("axis_dir") = std::array<double, 3>{0, 0, 1}, py::arg("angle_deg") = 360.0, py::arg("angle_param") = "w",
      py::kw_only(), py::arg("jacobian_samples") = 9,
      "A surface turned about an axis, exact and rational; angle_param ('u', 'v' or 'w') is the parameter along "
      "the angle. The scene file's 'revolve'.");
  m.def(
      "sweep",
      [](const py::handle& section, const py::handle& path, double twist_deg, int stations, const py::handle& initial_x,
         int jacobian_samples) {
        SweepParams p;
        p.twist_deg = twist_deg;
        p.stations = stations;
        if (!initial_x.is_none()) p.initial_x = to_vec3(initial_x, "initial_x");
        p.check = check_params(jacobian_samples);
        const TensorSpline s = spline_of(section), c = spline_of(path);
        return build([&] { return sweep(s, c, p); });
      },
      py::arg("section"), py::arg("path"), py::arg("twist_deg") = 0.0, py::arg("stations") = SweepParams{}.stations,
      py::arg("initial_x") = py::none(), py::kw_only(), py::arg("jacobian_samples") = 9,
      "A planar section (a surface in z = 0) swept along a curve with twist, in a rotation-minimising frame "
      "(approximate: exact at the stations). The scene file's 'sweep'.");
}

// The constructors from faces: coons, shell, and what prepares their faces.
void bind_face_constructors(py::module_& m) {
  m.def(
      "coons",
      [](const py::handle& faces, double edge_tolerance_relative, const py::object& untangle_settings,
         int jacobian_samples) {
        CoonsParams p;
        p.edge_tolerance_relative = edge_tolerance_relative;
        p.check = check_params(jacobian_samples);
        std::array<std::optional<TensorSpline>, 6> f;
        std::vector<TensorSpline> any_order;
        if (py::isinstance<py::dict>(faces)) {
          for (const auto& [key, value] : py::cast<py::dict>(faces)) {
            const std::string k = py::cast<std::string>(key);
            int i = 0;
            while (i < 6 && k != coons_face_name(i)) ++i;
            if (i == 6) throw py::value_error("coons: unknown face '" + k + "'; the faces are u0, u1, v0, v1, w0, w1");
            f[static_cast<std::size_t>(i)] = spline_of(value);
          }
          for (int i = 0; i < 6; ++i)
            if (!f[static_cast<std::size_t>(i)])
              throw py::value_error(std::string("coons: face ") + coons_face_name(i) + " is missing");
        } else {
          for (const py::handle s : faces) any_order.push_back(spline_of(s));
        }
        std::optional<UntangleParams> untangling;
        if (!untangle_settings.is_none() &&
            !(py::isinstance<py::bool_>(untangle_settings) && !untangle_settings.cast<bool>()))
          untangling =
              py::isinstance<py::dict>(untangle_settings) ? untangle_params(untangle_settings) : UntangleParams{};
        return build([&] {
          const std::array<TensorSpline, 6> six =
              any_order.empty() ? std::array<TensorSpline, 6>{*f[0], *f[1], *f[2], *f[3], *f[4], *f[5]}
                                : arrange_cube_faces(any_order);
          Constructed c = coons(six, p);
          if (!untangling) return c;
          // Only the interior control points move; the result is checked like any construction.
          UntangleResult r = untangle(c.volume.spline(), *untangling);
          Volume v(std::move(r.spline));
          ConstructionReport report = inspect_volume(v, p.check);
          report.constructor = "coons";
          return Constructed{std::move(v), std::move(report)};
        });
      },
      py::arg("faces"), py::kw_only(), py::arg("edge_tolerance_relative") = CoonsParams{}.edge_tolerance_relative,
      py::arg("untangle") = py::none(), py::arg("jacobian_samples") = 9,
      "The Coons volume of six faces: a dict {'u0': S, 'u1': ..., 'w1': ...}, or a list of six surfaces in any "
      "order and orientation (arranged by their corners, the first becoming w0). untangle: True or a dict "
      "(knots_per_span, iterations, samples_per_span, target) moves the interior control points until det J "
      "keeps one sign. The scene file's 'coons'.");
  m.def(
      "shell",
      [](const py::handle& surface, double thickness_mm, const std::string& side, int knots_per_span,
         int jacobian_samples) {
        ShellParams p;
        p.thickness_mm = thickness_mm;
        const std::optional<ShellSide> named = shell_side_from_name(side);
        if (!named) throw py::value_error("side must be 'outside', 'inside' or 'centred', got '" + side + "'");
        p.side = *named;
        p.knots_per_span = knots_per_span;
        p.check = check_params(jacobian_samples);
        const TensorSpline s = spline_of(surface);
        return build([&] { return thick_shell(s, p); });
      },
      py::arg("surface"), py::arg("thickness_mm"), py::arg("side") = "outside",
      py::arg("knots_per_span") = ShellParams{}.knots_per_span, py::kw_only(), py::arg("jacobian_samples") = 9,
      "A surface thickened along its normal (approximate offset). The scene file's 'shell' "
      "(trivox::thick_shell).");
  m.def(
      "join_surfaces",
      [](const std::vector<std::vector<py::object>>& grid, double edge_tolerance_relative) {
        std::vector<std::vector<TensorSpline>> rows;
        for (const auto& row : grid) {
          rows.emplace_back();
          for (const auto& s : row) rows.back().push_back(spline_of(s));
        }
        return join_surfaces(rows, JoinParams{edge_tolerance_relative});
      },
      py::arg("grid"), py::arg("edge_tolerance_relative") = JoinParams{}.edge_tolerance_relative,
      "One surface from a grid of surfaces meeting edge to edge (grid[row][column]; exact, C0 at the joints).");
}

// The untangling and the Jacobian report of any volume.
void bind_untangle(py::module_& m) {
  m.def(
      "arrange_cube_faces",
      [](const std::vector<py::object>& surfaces, double tolerance_relative) {
        std::vector<TensorSpline> s;
        for (const auto& o : surfaces) s.push_back(spline_of(o));
        const std::array<TensorSpline, 6> f = arrange_cube_faces(s, tolerance_relative);
        py::dict d;
        for (int i = 0; i < 6; ++i) d[coons_face_name(i)] = f[static_cast<std::size_t>(i)];
        return d;
      },
      py::arg("surfaces"), py::arg("tolerance_relative") = 1e-9,
      "Six surfaces of a closed cube-topology shell, in any order and orientation, as Coons faces {'u0': ...}.");
  m.def(
      "untangle",
      [](const py::handle& volume, const py::dict& settings) {
        const UntangleParams p = untangle_params(settings);
        const TensorSpline s = spline_of(volume);
        std::optional<UntangleResult> r;
        {
          py::gil_scoped_release release;
          r.emplace(untangle(s, p));
        }
        py::dict out;
        out["volume"] = std::make_shared<PyVolume>(Volume(std::move(r->spline)));
        out["iterations"] = r->iterations;
        out["below_target_before"] = r->below_target_before;
        out["below_target_after"] = r->below_target_after;
        out["min_relative_before"] = r->min_relative_before;
        out["min_relative_after"] = r->min_relative_after;
        return out;
      },
      py::arg("volume"), py::arg("settings") = py::dict(),
      "Moves a polynomial volume's interior control points until det J keeps one sign (construct/untangle.h); "
      "settings: knots_per_span, iterations, samples_per_span, target. Returns a dict with the volume and the "
      "objective's counts before and after.");
  m.def(
      "inspect_volume",
      [](const py::handle& volume, int jacobian_samples) {
        const PyVolume& v = py::cast<const PyVolume&>(volume);
        const JacobianCheckParams p = check_params(jacobian_samples);
        py::gil_scoped_release release;
        return inspect_volume(v.volume, p);
      },
      py::arg("volume"), py::arg("jacobian_samples") = 9,
      "The constructors' Jacobian report of any volume: where det J folds or vanishes on a sample grid.");
}

}  // namespace

void bind_construct(py::module_& m) {
  bind_report(m);
  bind_sweeps(m);
  bind_face_constructors(m);
  bind_untangle(m);
}

}  // namespace trivox::python
