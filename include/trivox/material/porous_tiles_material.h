// PorousTilesMaterial: the duck's porous microstructure (paper, Section 4 and Figure 3(d)).
// The cell's parametric domain, mapped onto [0,1]^3, is cut into tiles[0] x tiles[1] x
// tiles[2] boxes. From each box two orthogonal cylinders through the box's centre are
// removed (void); the rest of tile (i,j,k) is materials[(i+j+k) % 2], so neighbouring tiles
// alternate like a checkerboard.
//
// Cylinders are measured in tile coordinates, where every tile is the unit cube: a cylinder
// along axis a holds the points whose distance from the tile's centre line along a, taken
// in the two other coordinates, is below radius. In a tile of side 1 the void then has the
// volume 2 pi r^2 - 16/3 r^3 (two cylinders minus their Steinmetz intersection). On tiles
// that are not cubes in the cell's parameters, or on a curved cell, the holes follow the
// parametrization (elliptic in parameters, bent in space), as they did in the paper.
#pragma once

#include <array>

#include "trivox/material/material_function.h"

namespace trivox {

struct PorousTilesParams {
  std::array<int, 3> tiles{4, 4, 4};  // tiles along u, v, w; each >= 1
  double radius = 0.25;               // cylinder radius as a fraction of the tile side, in [0, 0.5]
  // Material of tiles with (i+j+k) even, and odd: material indices or kVoidMaterial.
  std::array<int, 2> materials{0, 1};
  // The tile axes the two cylinders run along (0 = u, 1 = v, 2 = w), distinct.
  std::array<int, 2> cylinder_axes{0, 1};

  // Throws Error naming the field and the rule.
  void validate(int num_materials) const;
};

class PorousTilesMaterial final : public MaterialFunction {
 public:
  PorousTilesMaterial(PorousTilesParams params, int num_materials, const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "porous_tiles"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // Exact where the box lies in one tile and clear of (or inside) both cylinders; otherwise
  // [0, 1] for the materials of the tiles it meets.
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;
  // Every sample is one material or void: the sum is at most the largest upper bound.
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

  const PorousTilesParams& params() const noexcept { return params_; }

 private:
  PorousTilesParams params_;
  AffineParamMap map_;  // cell parameters -> tile units: [0, tiles[d]] along d
};

}  // namespace trivox
