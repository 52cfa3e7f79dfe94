// A box cell trimmed by a mesh shell, for the tests of mesh trims: the scene's JSON, the meshes
// of ../shared/data/meshes with the scales that make each about 12 mm, and the box.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "trivox/math.h"

namespace trivox::test {

// A 203.2 dpi printer's scene of one box cell `box` (material graded along w) trimmed to the
// inside of the mesh at `mesh`, scaled by `scale`, by the inside rule `rule` ("even-odd" or
// "winding-number").
inline std::string scene_json(const std::filesystem::path& mesh, double scale, const Box3& box,
                              const std::string& rule) {
  std::string points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        points += fmt::format("{}[{:.17g}, {:.17g}, {:.17g}]", points.empty() ? "" : ", ", i ? box.hi.x : box.lo.x,
                              j ? box.hi.y : box.lo.y, k ? box.hi.z : box.lo.z);
  return fmt::format(
      R"({{"version": 1, "units": "mm", "printer": {{"x_dpi": 203.2, "y_dpi": 203.2, "layer_thickness_mm": 0.125, "max_materials": 2}},
  "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [{{"name": "trimmed", "geometry": {{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [{}]}},
    "trim": [{{"side": "inside", "shell": {{"mesh": "{}", "placement": {{"scale": {:.17g}}}, "inside_rule": "{}"}}}}],
    "material": {{"kind": "expression", "fractions": {{"VeroCyan": "w", "VeroMagenta": "1 - w"}}}}}}]}})",
      points, mesh.string(), scale, rule);
}

struct SharedMesh {
  const char* name;
  double scale;
};
inline constexpr SharedMesh kMeshes[] = {
    {"bunny.stl", 0.12}, {"torus.stl", 0.4}, {"M3_hex_nut.stl", 2.0}, {"sphere.stl", 0.4}, {"box.stl", 0.5}};

inline std::vector<std::array<Vec3, 3>> placed(std::vector<std::array<Vec3, 3>> soup, double scale) {
  for (auto& t : soup)
    for (Vec3& p : t) p = Vec3{scale * p.x, scale * p.y, scale * p.z};
  return soup;
}

// The cell's box: past the mesh on every side but +x and +z, where it cuts the mesh off, so
// that both the box and the mesh bound the material.
inline Box3 cell_box(const std::vector<std::array<Vec3, 3>>& soup) {
  Box3 m;
  for (const auto& t : soup)
    for (const Vec3& p : t) m.expand(p);
  const Vec3 size = m.hi - m.lo;
  return Box3{m.lo - Vec3{0.7, 0.9, 0.6}, {m.lo.x + 0.77 * size.x, m.hi.y + 0.8, m.lo.z + 0.83 * size.z}};
}

}  // namespace trivox::test
