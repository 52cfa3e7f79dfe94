#include "trivox/scene/starter_scene.h"

#include <array>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "trivox/error.h"
#include "trivox/printer/material_library.h"
#include "trivox/printer/printer_profile.h"

namespace trivox {

namespace {

std::string quoted(const std::string& text) { return nlohmann::json(text).dump(); }

std::vector<std::string> library_names() {
  std::vector<std::string> names;
  for (const LibraryMaterial& m : material_library()) names.emplace_back(m.name);
  return names;
}

// Shortest text that reads back to the same double.
std::string number(double x) { return fmt::format("{}", x); }

// The head every starter scene shares: version, description, units, printer, the two
// materials with their descriptions, the fraction policy and the dithering; then "cells".
std::string scene_head(const std::string& description, const PrinterProfile& printer,
                       const std::vector<std::string>& names, const std::array<std::string, 2>& material_descriptions) {
  std::string text;
  text += "{\n";
  text += "  \"version\": 1,\n";
  text += fmt::format("  \"description\": {},\n", quoted(description));
  text += "  \"units\": \"mm\",\n";
  text += fmt::format("  \"printer\": {},\n", quoted(printer.name));
  text += "  \"materials\": [\n";
  text +=
      fmt::format("    {{ \"name\": {}, \"description\": {} }},\n", quoted(names[0]), quoted(material_descriptions[0]));
  text +=
      fmt::format("    {{ \"name\": {}, \"description\": {} }}\n", quoted(names[1]), quoted(material_descriptions[1]));
  text += "  ],\n";
  text += "  \"fraction_sums\": { \"policy\": \"error\", \"tolerance\": 0.0001 },\n";
  text +=
      "  \"dithering\": { \"method\": \"floyd-steinberg\", \"serpentine\": true, \"vary_by_layer\": true, "
      "\"skin_voxels\": 0 },\n";
  text += "  \"cells\": [\n";
  return text;
}

// The cell's material, the expression "1 - p" for `a` and "p" for `b`, and the end of the
// cell, of "cells" and of the scene.
std::string gradient_and_end(const std::string& a, const std::string& b, const std::string& p) {
  std::string text;
  text += "      \"material\": {\n";
  text += "        \"kind\": \"expression\",\n";
  text += fmt::format("        \"fractions\": {{ {}: \"1 - {}\", {}: \"{}\" }}\n", quoted(a), p, quoted(b), p);
  text += "      }\n";
  text += "    }\n";
  text += "  ]\n";
  text += "}\n";
  return text;
}

std::string starter_mesh_scene_text(const StarterSceneParams& params, const PrinterProfile& printer,
                                    const std::vector<std::string>& names) {
  if (params.inside_rule != "even-odd" && params.inside_rule != "winding-number")
    throw Error(fmt::format("the inside rule '{}' is neither even-odd nor winding-number", params.inside_rule));
  const std::string& a = names[0];
  const std::string& b = names[1];
  const std::string mesh = quoted(params.mesh);
  const std::string rule = params.inside_rule == "even-odd" ? "" : ", \"inside_rule\": \"winding-number\"";
  const std::string description = fmt::format(
      "The part the triangle mesh {mesh} encloses, graded from {a} at its bottom to {b} at its top, written by "
      "`trivox init --mesh` to start from. printer: the built-in profile {p} ({layer} mm layers, {dpi_x} x {dpi_y} "
      "dpi, at most {max} materials per job; docs/PRINTING.md says which mode suits which job). materials: two "
      "library materials, named as the library spells them. fraction_sums: a sum of fractions above 1 stops "
      "slicing with an error. dithering: how fractions become one material per voxel (docs/DITHERING.md). cells: "
      "one cell whose volume is the box around the mesh (\"bounding_box\"), its parameters u, v and w running from "
      "0 to 1 along x, y and z, trimmed to the inside of the mesh (a shell trim, decided by the {rule} rule; "
      "docs/SCENE.md, \"Mesh trims\"). The mesh is taken in millimetres: to scale or move it, give the same "
      "\"placement\" to both \"mesh\" entries. Its material is an expression of w: {a} takes 1 - w and {b} w. "
      "`trivox info` on the mesh shows its size and checks; `trivox validate` checks the scene and estimates the "
      "job, `trivox slice` prints it.",
      fmt::arg("mesh", mesh), fmt::arg("a", a), fmt::arg("b", b), fmt::arg("p", printer.name),
      fmt::arg("layer", number(printer.layer_thickness_mm)), fmt::arg("dpi_x", number(printer.x_dpi)),
      fmt::arg("dpi_y", number(printer.y_dpi)), fmt::arg("max", printer.max_materials),
      fmt::arg("rule", params.inside_rule));
  std::string text = scene_head(description, printer, names,
                                {"all of the part at its bottom (w = 0), none at its top",
                                 "none of the part at its bottom, all at its top (w = 1)"});
  const std::string stem = std::filesystem::path(params.mesh).stem().string();
  text += "    {\n";
  text += fmt::format("      \"name\": {},\n", quoted(stem.empty() ? std::string("part") : stem));
  text += fmt::format("      \"geometry\": {{ \"bounding_box\": {{ \"mesh\": {} }} }},\n", mesh);
  text += fmt::format("      \"trim\": [ {{ \"side\": \"inside\", \"shell\": {{ \"mesh\": {}{} }} }} ],\n", mesh, rule);
  return text + gradient_and_end(a, b, "w");
}

}  // namespace

std::string starter_scene_text(const StarterSceneParams& params) {
  const PrinterProfile printer = builtin_printer_profile(params.printer);
  if (params.materials.size() != 2)
    throw Error(fmt::format("a starter scene grades between two materials, got {}", params.materials.size()));
  std::vector<std::string> names;
  for (const std::string& given : params.materials) {
    const auto m = find_library_material(given);
    if (!m)
      throw Error(
          fmt::format("'{}' is not a material of the library; known: {}", given, fmt::join(library_names(), ", ")));
    names.emplace_back(m->name);
  }
  if (names[0] == names[1]) throw Error(fmt::format("the two materials are both {}", names[0]));
  if (!params.mesh.empty()) return starter_mesh_scene_text(params, printer, names);
  const Vec3 s = params.size_mm;
  if (!(s.x > 0 && s.y > 0 && s.z > 0 && std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z)))
    throw Error(fmt::format("the box's size {} x {} x {} mm is not > 0", s.x, s.y, s.z));
  const std::string x = number(s.x), y = number(s.y), z = number(s.z);
  const std::string a = names[0], b = names[1];

  const std::string description = fmt::format(
      "A {x} x {y} x {z} mm box graded from {a} at x = 0 to {b} at x = {x} mm, written by `trivox init` to start "
      "from. printer: the built-in profile {p} ({layer} mm layers, {dpi_x} x {dpi_y} dpi, at most {max} materials "
      "per job; docs/PRINTING.md says which mode suits which job). materials: two library materials, named as "
      "the library spells them, each shown in the images in the library's colour. fraction_sums: a sum of "
      "fractions above 1 stops slicing with an error (\"normalise\" would scale it down instead). dithering: "
      "how fractions become one material per voxel (docs/DITHERING.md). cells: one cell, the box, an inline "
      "trilinear volume whose eight corner points are its corners; its parameters u, v and w run from 0 to 1 "
      "along x, y and z. Its material is an expression of u: {a} takes 1 - u and {b} u, so they always sum to "
      "1 and nothing is void. To change it: move the corner points to resize the box, name other library "
      "materials (or give a name and an rgba of your own), or write other expressions (docs/SCENE.md); `trivox "
      "validate` checks the scene and estimates the job, `trivox slice` prints it.",
      fmt::arg("x", x), fmt::arg("y", y), fmt::arg("z", z), fmt::arg("a", a), fmt::arg("b", b),
      fmt::arg("p", printer.name), fmt::arg("layer", number(printer.layer_thickness_mm)),
      fmt::arg("dpi_x", number(printer.x_dpi)), fmt::arg("dpi_y", number(printer.y_dpi)),
      fmt::arg("max", printer.max_materials));

  std::string text = scene_head(description, printer, names,
                                {fmt::format("all of the box at x = 0 (u = 0), none at x = {} mm", x),
                                 fmt::format("none of the box at x = 0, all at x = {} mm (u = 1)", x)});
  text += "    {\n";
  text += "      \"name\": \"box\",\n";
  text += "      \"geometry\": {\n";
  text += "        \"orders\": [2, 2, 2],\n";
  text += "        \"knots\": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],\n";
  text += fmt::format("        \"points\": [[0, 0, 0], [{x}, 0, 0], [0, {y}, 0], [{x}, {y}, 0],\n", fmt::arg("x", x),
                      fmt::arg("y", y));
  text += fmt::format("                   [0, 0, {z}], [{x}, 0, {z}], [0, {y}, {z}], [{x}, {y}, {z}]]\n",
                      fmt::arg("x", x), fmt::arg("y", y), fmt::arg("z", z));
  text += "      },\n";
  return text + gradient_and_end(a, b, "u");
}

}  // namespace trivox
