// Proving a cell's fraction rules before slicing: that its material function never gives a
// fraction below 0 or a sum above 1 (beyond the scene's tolerance), nor a value that is not a
// finite number, anywhere in the cell's parametric domain; or finding a point where it does.
//
// Branch and bound over boxes of the domain: each box's enclosure (MaterialFunction::enclose,
// with the rounding to float added) either proves the rules there, or the material is
// evaluated at the box's centre, where it may break them (a witness), or the box is split in
// two along the direction whose halves the bounds judge best (so that a thin band of bad
// values is cut off along its thin direction). Boxes are examined worst bound first. When the budget of boxes runs out,
// or a box is too narrow to split, with its bounds still inconclusive, the outcome is "cannot prove": the rules may
// hold, but the bounds are too loose to show it (an expression whose terms cancel in a way interval arithmetic and the
// mean-value form do not see, a texture whose channels sum above 1 somewhere).
#pragma once

#include <string>
#include <vector>

#include "trivox/material/material_function.h"
#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct FractionCheckParams {
  int max_boxes = 20000;           // boxes examined per cell before the check gives up
  double min_box_relative = 1e-7;  // a box narrower than this share of the domain in every direction is not split
};

enum class FractionCheckOutcome {
  kProved,    // the rules hold everywhere in the domain
  kBroken,    // the material breaks them at a point (the witness)
  kUnproved,  // the bounds stayed inconclusive somewhere
};

struct FractionCheck {
  FractionCheckOutcome outcome = FractionCheckOutcome::kProved;
  // Proved: the largest sum and the smallest fraction the bounds allow (the policy's sum:
  // fractions below 0 count as 0); under "normalise" only finiteness is proved.
  double sum_bound = 0.0, fraction_bound = 0.0;
  // Broken: where (the cell's parameters, the position in mm) and the rule, e.g. "the fractions
  // sum to 1.3 > 1 (tolerance 0.0001)".
  Vec3 uvw{}, xyz{};
  std::string rule;
  // Unproved: the first box (the cell's parameters) where the bounds stayed inconclusive and
  // what they allowed there, e.g. "the sum may reach 1.02".
  ParamBox box{};
  std::string reason;
  int boxes = 0;  // boxes examined
};

// Checks `material` (a cell's function before its fraction policy, m names for messages)
// over the whole domain of `geometry` (the cell's volume, its placement applied: it bounds
// the positions the material sees). Thread-safe; allocates per box.
FractionCheck check_fractions(const MaterialFunction& material, const FractionPolicy& policy,
                              const TensorSpline& geometry, const std::vector<std::string>& material_names,
                              const FractionCheckParams& params = {});

}  // namespace trivox
