// What every volume constructor (include/trivox/construct/) returns beside the volume: the
// sampled Jacobian check of the result and where in the parameter domain it folds or
// degenerates, and how far an approximate construction may be from its ideal shape.
#pragma once

#include <string>

#include "trivox/math.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/volume.h"

namespace trivox {

// Samples of det J on the check grid that share one property, and the parameter box that
// holds them all (meaningful only when samples > 0).
struct JacobianRegion {
  int samples = 0;
  ParamBox box;
};

struct ConstructionReport {
  std::string constructor;  // "extrude", "ruled", "revolve", "sweep", "coons", "shell"
  JacobianReport jacobian;  // classification and sample counts (spline/jacobian_check.h)
  // Samples whose det J has the sign of the minority (the folded part when the volume folds:
  // det J < 0 where most samples are > 0, or the reverse), and samples where det J is zero.
  JacobianRegion minority_sign;
  JacobianRegion zero;
  // False for the approximate constructions (sweep, thick shell); then
  // approximation_error_mm bounds, from samples, how far the volume is from the ideal shape
  // the construction aims at (see each constructor's header).
  bool exact = true;
  double approximation_error_mm = 0.0;

  bool folds() const noexcept { return jacobian.classification == JacobianClass::kFolded; }
  // One line: the Jacobian's classification, and where the volume folds or degenerates, e.g.
  // "folded: det J < 0 at 12 of 729 samples, in u [0.5, 1] v [0, 1] w [0.25, 0.5]".
  std::string describe() const;
};

struct Constructed {
  Volume volume;
  ConstructionReport report;
};

// Samples det J of `volume` on the grid of `params` (both domain ends included) and fills
// the report's Jacobian fields.
ConstructionReport inspect_volume(const Volume& volume, const JacobianCheckParams& params);

}  // namespace trivox
