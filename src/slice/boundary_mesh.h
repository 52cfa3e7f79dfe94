// The boundary of a cell (the six faces of its trivariate) as a watertight triangle mesh,
// built once per cell and cut by every layer's plane into the cell's outline.
//
// Watertight by construction: each parametric direction d is sampled at one set of n_d
// parameters shared by every face, so two faces that meet along an edge of the volume
// evaluate V at the same parameters there and get bit-identical vertices.
#pragma once

#include <array>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/volume.h"

namespace trivox::detail {

struct Segment2 {
  double x0, y0, x1, y1;
};

class BoundaryMesh {
 public:
  // Refines the sampling until every grid cell of every face deviates from its bilinear
  // patch and from its two triangles by at most `tolerance_mm` at its centre (or a direction
  // reaches 4096 samples).
  BoundaryMesh(const Volume& volume, double tolerance_mm);

  const Box3& bounds() const noexcept { return bounds_; }
  std::array<int, 3> samples() const noexcept { return n_; }
  std::size_t triangle_count() const noexcept { return triangles_.size(); }

  // The outline at height z: one segment per triangle crossing the plane, with the crossing
  // points computed from each edge in a fixed vertex order so shared edges give identical
  // points (an even-odd scan then never double counts).
  void cut(double z, std::vector<Segment2>& out) const;

 private:
  std::array<int, 3> n_{};
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  Box3 bounds_;
  // Triangles bucketed by height so a cut touches only the nearby ones.
  double bucket_z0_ = 0, bucket_dz_ = 1;
  std::vector<std::vector<int>> buckets_;
};

}  // namespace trivox::detail
