// A small scene for tests of the program's rules (a few milliseconds per layer): one
// trilinear box cell of `size_mm` on the J750 in High Mix mode (or `printer`), one constant
// material per name, the cell made of the first. Header-only: the test build compiles
// *_test.cpp files only.
#pragma once

#include <string>
#include <vector>

#include <fmt/format.h>

namespace trivox::test {

inline std::string small_box_scene(const std::vector<std::string>& materials = {"VeroCyan"}, double size_mm = 4,
                                   const std::string& printer = "\"j750-hm\"") {
  std::string points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        points += fmt::format("{}[{}, {}, {}]", points.empty() ? "" : ", ", size_mm * i, size_mm * j, size_mm * k);
  std::string list;
  for (const std::string& m : materials) list += fmt::format("{}{{\"name\": \"{}\"}}", list.empty() ? "" : ", ", m);
  return fmt::format(R"({{"version": 1, "units": "mm", "printer": {},
 "materials": [{}],
 "cells": [{{"name": "box", "geometry": {{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [{}]}},
   "material": {{"kind": "constant", "fractions": {{"{}": 1}}}}}}]}})",
                     printer, list, points, materials.front());
}

}  // namespace trivox::test
