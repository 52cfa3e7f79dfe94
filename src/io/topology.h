// The topology of a multi-patch model in G+Smo's terms (gsBoxTopology): which sides of the
// patches are shared by two of them (interfaces) and which lie on the model's boundary. The
// G+Smo writer stores it in the <MultiPatch> element, so a model opens in G+Smo as one
// connected domain.
#pragma once

#include <array>
#include <vector>

#include "trivox/io/model.h"

namespace trivox {

// A side of a patch, numbered as G+Smo numbers them (gsBoundary.h, boxSide): 1 and 2 are
// u = lo and u = hi, 3 and 4 are v = lo and v = hi, 5 and 6 are w = lo and w = hi.
struct PatchSide {
  int patch = 0;  // index into Model::patches
  int side = 1;
  int direction() const noexcept { return (side - 1) / 2; }
  bool at_end() const noexcept { return (side - 1) % 2 == 1; }
  bool operator==(const PatchSide&) const = default;
  auto operator<=>(const PatchSide&) const = default;
};

// Two sides that are one face of the model, with G+Smo's description of how their parameters
// meet (boundaryInterface): direction i of the first patch runs along direction dir_map[i] of
// the second, the same way when dir_orientation[i] is true. For the direction normal to the
// side, dir_map gives the second side's normal direction and dir_orientation says that one
// side is at its patch's lower end and the other at its upper end. Only the first param_dim
// entries are used.
struct PatchInterface {
  PatchSide first, second;
  std::array<int, 3> dir_map{0, 1, 2};
  std::array<bool, 3> dir_orientation{true, true, true};
  bool operator==(const PatchInterface&) const = default;
};

struct PatchTopology {
  std::vector<PatchInterface> interfaces;  // first < second; ordered by first
  std::vector<PatchSide> boundary;         // every side in no interface, in order
};

// Finds the interfaces among the sides of `model`'s patches, which must all have one
// param_dim: two sides form one when they are the same face with the same parametrization up
// to a permutation and reversal of its directions (the face's corners, its centre and a
// 5^(param_dim - 1) grid of its points, at parameters normalised to each patch's domain,
// agree within `tolerance_relative` times the diagonal of the model's control-point box). A
// side matches at most one other (a closed patch may match one of its own sides with
// another). Throws ModelError when the patches differ in param_dim.
PatchTopology find_topology(const Model& model, double tolerance_relative = 1e-8);

}  // namespace trivox
