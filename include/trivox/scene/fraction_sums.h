// The scene's fraction rules checked before slicing (`trivox validate`): for every cell, a
// proof that its material never breaks the scene's fraction policy over the cell's domain,
// a point where it does, or "cannot prove" (material/fraction_check.h).
#pragma once

#include <string>
#include <vector>

#include "trivox/material/fraction_check.h"
#include "trivox/scene/scene.h"

namespace trivox {

struct CellFractionCheck {
  int cell = 0;  // index into Scene::cells
  FractionCheck check;
};

// One entry per cell, in scene order. A cell that is trimmed (by clauses, or a region of a
// union) is checked over its whole volume; a point where its material breaks the rule may
// then lie outside the cell, so there it counts as "cannot prove", the point named in the
// reason.
std::vector<CellFractionCheck> check_scene_fractions(const Scene& scene, const FractionCheckParams& params = {});

// The scene's greyscale source where it is a scalar source (Cell::grey_source): for every cell
// that has one, a proof that its values are finite numbers over the cell's domain (the check
// of the "normalise" policy, which proves only that), a point where one is not (the slicer
// stops there), or "cannot prove". Cells without one have no entry.
std::vector<CellFractionCheck> check_scene_grey_sources(const Scene& scene, const FractionCheckParams& params = {});

}  // namespace trivox
