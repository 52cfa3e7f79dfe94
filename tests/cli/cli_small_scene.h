// A small scene for tests of the program's rules (a few milliseconds per layer): one
// trilinear box cell of `size_mm` on the J750 in High Mix mode (or `printer`), one constant
// material per name (each in a colour of its own), the cell made of the first. Header-only: the test build compiles
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
  // A colour of its own for each (any name is then a valid material), all distinct.
  for (std::size_t i = 0; i < materials.size(); ++i)
    list += fmt::format("{}{{\"name\": \"{}\", \"rgba\": [{}, {}, {}, 255]}}", i == 0 ? "" : ", ", materials[i],
                        20 + 20 * i % 220, 100 + i / 11, 200);
  return fmt::format(R"({{"version": 1, "units": "mm", "printer": {},
 "materials": [{}],
 "cells": [{{"name": "box", "geometry": {{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [{}]}},
   "material": {{"kind": "constant", "fractions": {{"{}": 1}}}}}}]}})",
                     printer, list, points, materials.front());
}

}  // namespace trivox::test
