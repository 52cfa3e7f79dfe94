#include "trivox/material/porous_tiles_material.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

void PorousTilesParams::validate(int num_materials) const {
  for (std::size_t d = 0; d < 3; ++d)
    if (tiles[d] < 1) throw Error(fmt::format("porous tiles: tiles[{}] = {} is not >= 1", d, tiles[d]));
  if (!std::isfinite(radius) || radius < 0.0 || radius > 0.5)
    throw Error(
        fmt::format("porous tiles: radius {} is not in [0, 0.5] (a fraction of the "
                    "tile side; 0.5 makes the cylinders touch the tile's faces)",
                    radius));
  for (std::size_t t = 0; t < 2; ++t)
    if (materials[t] != kVoidMaterial && (materials[t] < 0 || materials[t] >= num_materials))
      throw Error(
          fmt::format("porous tiles: materials[{}] = {} is not a material index in "
                      "[0, {}) nor void",
                      t, materials[t], num_materials));
  for (std::size_t t = 0; t < 2; ++t)
    if (cylinder_axes[t] < 0 || cylinder_axes[t] > 2)
      throw Error(
          fmt::format("porous tiles: cylinder_axes[{}] = {} is not 0 (u), 1 (v) or 2 (w)", t, cylinder_axes[t]));
  if (cylinder_axes[0] == cylinder_axes[1])
    throw Error("porous tiles: the two cylinders must run along different axes");
}

namespace {

// The two tile coordinates across a cylinder that runs along `axis`.
std::array<int, 2> across(int axis) noexcept {
  return axis == 0 ? std::array<int, 2>{1, 2} : (axis == 1 ? std::array<int, 2>{0, 2} : std::array<int, 2>{0, 1});
}

}  // namespace

PorousTilesMaterial::PorousTilesMaterial(PorousTilesParams params, int num_materials, const ParamBox& cell_domain)
    : MaterialFunction(num_materials), params_(params) {
  params_.validate(num_materials);
  const ParamBox tile_units{{0.0, 0.0, 0.0},
                            {static_cast<double>(params_.tiles[0]), static_cast<double>(params_.tiles[1]),
                             static_cast<double>(params_.tiles[2])}};
  map_ = AffineParamMap::between(cell_domain, tile_units);
}

void PorousTilesMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                       std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const double r2 = params_.radius * params_.radius;
  const std::array<int, 2> c0 = across(params_.cylinder_axes[0]);
  const std::array<int, 2> c1 = across(params_.cylinder_axes[1]);
  // Zeros for the whole row at once, then a single 1 per sample of material.
  std::fill(fractions.begin(), fractions.begin() + static_cast<std::ptrdiff_t>(uvw.size() * m), 0.0f);
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    int parity = 0;
    Vec3 local;  // position inside the tile, in [0,1]^3, relative to the tile's centre
    for (int d = 0; d < 3; ++d) {
      const int n = params_.tiles[static_cast<std::size_t>(d)];
      const double t = std::clamp(p[d], 0.0, static_cast<double>(n));
      const int i = std::min(static_cast<int>(t), n - 1);
      parity += i;
      local[d] = t - i - 0.5;
    }
    const double d0 = local[c0[0]] * local[c0[0]] + local[c0[1]] * local[c0[1]];
    const double d1 = local[c1[0]] * local[c1[0]] + local[c1[1]] * local[c1[1]];
    float* f = fractions.data() + s * m;
    const int material = params_.materials[static_cast<std::size_t>(parity & 1)];
    if (material != kVoidMaterial && d0 >= r2 && d1 >= r2) f[material] = 1.0f;
  }
}

void PorousTilesMaterial::bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const {
  const auto m = static_cast<std::size_t>(num_materials());
  std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  std::fill(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  const ParamBox t = map_(box);
  std::array<int, 3> first{}, last{};
  Vec3 a, b;  // the box relative to the centre of tile `first` (meaningful in one tile)
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    const int n = params_.tiles[dd];
    const double tlo = std::clamp(std::min(t.lo[d], t.hi[d]), 0.0, static_cast<double>(n));
    const double thi = std::clamp(std::max(t.lo[d], t.hi[d]), 0.0, static_cast<double>(n));
    first[dd] = std::min(static_cast<int>(tlo), n - 1);
    last[dd] = std::min(static_cast<int>(thi), n - 1);
    a[d] = tlo - first[dd] - 0.5;
    b[d] = thi - first[dd] - 0.5;
  }
  const bool one_tile = first == last;
  const int parity = (first[0] + first[1] + first[2]) & 1;
  for (int q = 0; q < 2; ++q) {
    if (one_tile && q != parity) continue;
    const int material = params_.materials[static_cast<std::size_t>(q)];
    if (material != kVoidMaterial) hi[static_cast<std::size_t>(material)] = 1.0f;
  }
  if (!one_tile) return;
  // In one tile: squared distances of the box from each cylinder's axis, nearest and farthest.
  const double r2 = params_.radius * params_.radius;
  bool clear = true, inside = false;
  for (int axis : params_.cylinder_axes) {
    double near2 = 0.0, far2 = 0.0;
    for (int d : across(axis)) {
      const double gap = std::max({0.0, a[d], -b[d]});
      const double reach = std::max(std::abs(a[d]), std::abs(b[d]));
      near2 += gap * gap;
      far2 += reach * reach;
    }
    clear = clear && near2 >= r2;
    inside = inside || far2 < r2;
  }
  const int material = params_.materials[static_cast<std::size_t>(parity)];
  if (material == kVoidMaterial) return;
  const auto j = static_cast<std::size_t>(material);
  if (inside) hi[j] = 0.0f;
  if (clear) lo[j] = 1.0f;
}

FractionEnclosure PorousTilesMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  FractionEnclosure e = MaterialFunction::enclose(box, xyz);
  e.sum_of_one_material();
  return e;
}

}  // namespace trivox
