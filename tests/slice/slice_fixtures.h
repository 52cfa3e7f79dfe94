// Small scenes built in code for the slicer tests.
#pragma once

#include <memory>
#include <string>

#include "support/test_support.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/detail/spline_field_material.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/scene/scene.h"

namespace trivox::test {

// An axis-aligned box [lo, hi] (mm) as a trilinear volume on [0,1]^3.
inline Volume box_volume(Vec3 lo, Vec3 hi) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z});
  return Volume(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts));
}

inline Scene scene_with(std::vector<Cell> cells, int num_materials, const std::string& printer = "j750-hq") {
  Scene s;
  s.source = "test-scene";
  s.printer = builtin_printer_profile(printer);
  const std::array<std::array<std::uint8_t, 4>, 4> colours = {
      {{0, 255, 255, 255}, {255, 0, 255, 255}, {255, 255, 0, 255}, {0, 0, 0, 255}}};
  for (int j = 0; j < num_materials; ++j)
    s.materials.push_back({std::string("m").append(std::to_string(j)), colours[static_cast<std::size_t>(j)], {}});
  s.cells = std::move(cells);
  return s;
}

inline Cell constant_cell(Volume v, int material, int num_materials, const std::string& name = "cell") {
  std::vector<float> f(static_cast<std::size_t>(num_materials), 0.0f);
  f[static_cast<std::size_t>(material)] = 1.0f;
  return Cell{name, "/cells/0", std::move(v), std::make_shared<ConstantMaterial>(f)};
}

// Material 0 rises linearly from 0 to 1 along u; material 1 takes the rest.
inline Cell gradient_cell(Volume v) {
  const TensorSpline field({KnotVector::bezier(2), KnotVector(1, {0, 1}), KnotVector(1, {0, 1})}, 2, {0, 1, 1, 0});
  auto m = std::make_shared<SplineFieldMaterial>(field, std::vector<int>{0, 1}, 2, v.domain());
  return Cell{"gradient", "/cells/0", std::move(v), m};
}

}  // namespace trivox::test
