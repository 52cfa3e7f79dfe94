// Orientation check of a trivariate from samples of its Jacobian determinant.
#pragma once

#include <string_view>

#include "trivox/spline/volume.h"

namespace trivox {

enum class JacobianClass {
  kRightHanded,  // det J > 0 at every sample
  kLeftHanded,   // det J < 0 at every sample (valid: the cell is mirrored, not inside-out)
  kDegenerate,   // det J vanishes at some sample (collapsed face or edge), never changes sign
  kFolded,       // det J takes both signs: the volume folds over itself
};

std::string_view to_string(JacobianClass c) noexcept;

struct JacobianCheckParams {
  int samples_per_direction = 7;  // grid points per direction, both domain ends included
  // A determinant counts as zero when |det| <= this fraction of the largest |det| sampled.
  double zero_relative = 1e-9;
};

struct JacobianReport {
  JacobianClass classification = JacobianClass::kRightHanded;
  int positive = 0, negative = 0, zero = 0;  // sample counts
  double min_det = 0, max_det = 0;
};

JacobianReport check_jacobian(const Volume& v, const JacobianCheckParams& params = {});

}  // namespace trivox
