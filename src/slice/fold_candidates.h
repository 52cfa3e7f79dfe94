// Candidate pixels of a folded trivariate. The outline of an ordinary cell (its boundary
// mesh cut by the layer, filled by the even-odd rule) misses the pixels that a fold covers
// twice, where the parity cancels, and those beyond the image of the boundary that the fold's
// crease reaches. A folded cell (docs/SCENE.md, "Folded cells") therefore takes as candidates
// every pixel whose centre lies in the box of a Bezier piece's control points that the layer
// crosses: by the convex hull property each piece's image lies in its box, so no pixel with a
// preimage is left out. The global solver then decides each candidate.
#pragma once

#include <vector>

#include "scanline.h"
#include "trivox/math.h"
#include "trivox/spline/volume.h"

namespace trivox::detail {

class FoldCandidates {
 public:
  explicit FoldCandidates(const Volume& volume);

  // The pixels of the layer at z_mm whose centre lies within margin_mm of the box of a piece
  // whose z range, widened by margin_mm, holds z_mm; merged spans per row.
  void spans(const SliceLayout& layout, double z_mm, double margin_mm, RowSpans& rows) const;

 private:
  std::vector<Box3> boxes_;
};

}  // namespace trivox::detail
