// What the whole-job benchmarks share: the duck-class scene and argument parsing.
#pragma once

#include <cstring>
#include <memory>
#include <string>

#include "support/test_support.h"
#include "trivox/material/porous_tiles_material.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/scene/scene.h"

namespace trivox::bench {

// The duck-class job of docs/PERFORMANCE.md: a cubic 8x8x8 trivariate, bent and twisted,
// filling a box of 128 x 128 x 88 mm (times `scale`), with the porous-tiles material, on the
// Stratasys J750 at 600 x 300 dpi and 30 um layers (the paper's settings).
inline Scene duck_class_scene(double scale) {
  Scene s;
  s.source = "duck-class benchmark";
  s.printer = builtin_printer_profile("j750-paper");
  s.materials = {{"green", {40, 170, 60, 255}, ""}, {"blue", {30, 80, 200, 255}, ""}};
  Volume v = test::twisted_bent_box(128 * scale, 128 * scale, 88 * scale, 8, 4);
  PorousTilesParams tiles;
  tiles.tiles = {6, 6, 4};
  tiles.radius = 0.3;
  auto material = std::make_shared<PorousTilesMaterial>(tiles, 2, v.domain());
  s.cells.push_back(Cell{"duck-class", "/cells/0", std::move(v), material});
  return s;
}

inline int arg_int(int argc, char** argv, const char* name, int fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return std::stoi(argv[i + 1]);
  return fallback;
}

inline double arg_double(int argc, char** argv, const char* name, double fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return std::stod(argv[i + 1]);
  return fallback;
}

inline bool has_flag(int argc, char** argv, const char* name) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], name) == 0) return true;
  return false;
}

}  // namespace trivox::bench
