// What the slicer (slicer.cpp) and the edge coverage of greyscale layers (coverage.h) both
// prepare from a scene's cells before the first layer, each at its own tolerances: which
// trivariate inverts each cell and each volume clause, and the meshes of the trim shells. One
// preparation, so that the sub-samples of an edge pixel are decided by the same trivariates
// and the same kind of tessellation as the pixels around it.
#pragma once

#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "trivox/scene/scene.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox::detail {

// The trivariates a scene's cells are inverted in: a named volume is one trivariate however
// many cells and clauses use it, numbered when first used (in scene order: a cell's own
// volume, then the volumes of its clauses); a cell with a geometry of its own has one of its
// own.
struct TrivariatePlan {
  struct Trivariate {
    const Volume* volume;
    bool folds;  // a folded volume the scene accepts (SceneVolume::folds, Cell::folds)
  };
  std::vector<Trivariate> trivariates;
  std::vector<int> of_cell;                 // per cell
  std::vector<std::vector<int>> of_clause;  // per cell and clause: a kVolume clause's trivariate, else -1
};

TrivariatePlan plan_trivariates(const Scene& scene);

// The tessellations of the trim shells of kShell and kParametric clauses, each built on first
// use and shared by every clause that names the same shell (for a parametric shell, of the
// same cell). A model-space shell is tessellated within `shell_tolerance_mm`; a parametric one
// within 1e-4 of the cell's parameter box, and further until its image through the cell's
// volume (clamped to the domain, so a trim reaching past a face of the domain maps onto it)
// lies within `outline_tolerance_mm` of the map of the surfaces.
class TrimShellMeshes {
 public:
  TrimShellMeshes(double shell_tolerance_mm, double outline_tolerance_mm)
      : shell_tolerance_mm_(shell_tolerance_mm), outline_tolerance_mm_(outline_tolerance_mm) {}

  // The mesh of `clause` (kShell or kParametric) of cell `c`, at most `max_samples` per
  // direction (ShellMesh's constructors) when this call builds it.
  std::shared_ptr<const ShellMesh> mesh(const Cell& c, const TrimClause& clause, int max_samples = 1024);
  // A kParametric clause's mesh (mesh() must have given it) mapped through the cell's volume:
  // the clause's outline in model space.
  std::shared_ptr<const ShellMesh> outline(const Cell& c, const TrimClause& clause);

 private:
  using Key = std::pair<const TrimShell*, const Cell*>;
  double shell_tolerance_mm_, outline_tolerance_mm_;
  std::map<Key, std::shared_ptr<const ShellMesh>> meshes_, outlines_;
};

}  // namespace trivox::detail
