// A scene to start from (`trivox init`): a box graded between two library materials, every
// part said in words in its "description" fields, valid as written and sliceable as is.
#pragma once

#include <string>
#include <vector>

#include "trivox/math.h"

namespace trivox {

struct StarterSceneParams {
  std::string printer = "j750-hm";  // a built-in printer profile
  // Exactly two distinct library materials (printer/material_library.h): the first at
  // x = 0, the second at the far end of the box.
  std::vector<std::string> materials{"VeroCyan", "VeroMagenta"};
  Vec3 size_mm{20.0, 10.0, 5.0};  // the box, from the origin; each > 0
  // A triangle mesh file instead of the box, named as the scene writes it (relative to the
  // scene's folder): the cell is the box around the mesh ("bounding_box") trimmed to the mesh,
  // graded from the first material at its bottom to the second at its top. size_mm is then
  // unused.
  std::string mesh;
  // How the mesh decides inside: "even-odd" (a closed, oriented mesh) or "winding-number".
  std::string inside_rule = "even-odd";
};

// The scene as JSON text (docs/SCENE.md): the printer, the two materials, the fraction policy
// and the dithering written out with their defaults, and one cell, an inline trilinear box
// whose u, v, w run along x, y, z, with the expression material "1 - u" and "u" (with a mesh:
// the box around it trimmed by it, "1 - w" and "w"). Names are
// written as the library spells them. Throws Error for an unknown printer or material, a
// material count other than two, the same material twice, or a size that is not > 0.
std::string starter_scene_text(const StarterSceneParams& params);

}  // namespace trivox
