// Orientation check of a trivariate from samples of its Jacobian determinant.
#pragma once

#include <string_view>
#include <vector>

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

// Throws ModelError (the volume's numbers overflow) when det J at a sample is infinite or NaN:
// coordinates or derivatives beyond double range are no orientation, and classifying them as
// zeros would call the volume degenerate.
JacobianReport check_jacobian(const Volume& v, const JacobianCheckParams& params = {});

// Where a folded volume folds, from the samples of check_jacobian: the samples whose det J
// has the minority sign (det J < 0 where at least as many samples are > 0, else det J > 0),
// grouped into sets connected on the grid (through faces, edges or corners), each set's box
// grown by one grid step on every side (within the domain: the sign changes somewhere
// between a sample and its neighbours) and boxes that then overlap merged. Sorted by their
// lower corner (u, then v, then w). Empty unless the volume is kFolded.
struct FoldRegion {
  ParamBox box;
  int samples = 0;  // minority samples inside
};
std::vector<FoldRegion> fold_regions(const Volume& v, const JacobianCheckParams& params = {});

}  // namespace trivox
