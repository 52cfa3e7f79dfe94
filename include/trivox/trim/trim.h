// Trimming of a cell (paper, Section 3: FGM_cell = {V, M, S}). A cell keeps one
// parametrization V and one material M; its set S of trims is a list of clauses, and the
// cell's pixels are those inside V that satisfy every clause:
//  * kVolume: inside (or outside) another trivariate of the scene, decided by that
//    trivariate's exact inverse, so cells trimmed by each other's volumes (the Boolean cells
//    "A only", "B only", "A and B") partition their union;
//  * kShell: inside (or outside) a closed set of surfaces in model space (mm), or a closed
//    triangle mesh there (a mesh trim: a mesh file's triangles);
//  * kParametric: the cell's (u, v, w) inside (or outside) a closed set of surfaces drawn in
//    V's parametric domain.
// Shells are decided on a watertight tessellation (detail/shell_mesh.h) within a tolerance far
// below a pixel.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/mesh/sliced_mesh.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

enum class TrimSide { kInside, kOutside };
enum class TrimKind { kVolume, kShell, kParametric };
std::string_view to_string(TrimSide s) noexcept;
std::string_view to_string(TrimKind k) noexcept;

// A closed set of surfaces (two parameters, three coordinates each): model space (mm) for a
// shell trim, the (u, v, w) of the cell's volume for a parametric trim. Closed means the
// surfaces meet along their edges with no gap (detail/shell_mesh.h checks it).
// A surface restricted to loops of curves in its parameter space (a trimmed surface of an
// IRIT MODEL). The kept part is the even-odd interior of the loops.
struct TrimmedSurface {
  struct Piece {
    TensorSpline curve;  // in the surface's (u, v), two coordinates
    bool reversed = false;
    int segment = -1;  // the trimming segment it comes from, shared by the surfaces it borders
  };
  std::string name;  // for messages, e.g. "MODEL 'TEAPOT', trimmed surface 2"
  TensorSpline surface;
  std::vector<std::vector<Piece>> loops;
};

// How a mesh trim decides inside and outside (docs/SCENE.md, "Mesh trims").
enum class InsideRule {
  // The even-odd rule on the mesh's cut, exact per pixel; the mesh must be closed (the
  // scene reader checks it with trivox/mesh/detail/mesh_check.h).
  kEvenOdd,
  // The generalized winding number at least 1/2, after the orientation is repaired: tolerates
  // gaps, flipped triangles and parts that overlap (their union is inside).
  kWindingNumber,
};
std::string_view to_string(InsideRule r) noexcept;

struct TrimShell {
  std::string name;  // for messages: the file it came from, or the scene pointer
  std::vector<TensorSpline> surfaces;
  // Trimmed surfaces. Their tessellations meet only within the accuracy of the trimming
  // curves, so a shell with any is decided by a test robust to hairline gaps (detail/shell_mesh.h).
  std::vector<TrimmedSurface> trimmed;
  // A triangle mesh instead of surfaces (a mesh trim), already placed, and its rule.
  std::shared_ptr<const SlicedMesh> mesh;
  InsideRule rule = InsideRule::kEvenOdd;
};

struct TrimClause {
  TrimKind kind = TrimKind::kVolume;
  TrimSide side = TrimSide::kInside;
  // kVolume: index into Scene::volumes.
  int volume = -1;
  // kShell, kParametric: the surfaces (shared between cells that use the same shell).
  std::shared_ptr<const TrimShell> shell;
};

struct Trim {
  std::vector<TrimClause> clauses;

  bool empty() const noexcept { return clauses.empty(); }
};

}  // namespace trivox
