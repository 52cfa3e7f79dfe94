#include "trivox/material/detail/spline_field_material.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "material/spline_coefficient_bounds.h"
#include "trivox/error.h"

namespace trivox {

namespace {

ParamBox spline_domain(const TensorSpline& s) { return {{s.lo(0), s.lo(1), s.lo(2)}, {s.hi(0), s.hi(1), s.hi(2)}}; }

void validate_field(const TensorSpline& field, const std::vector<int>& component_material, int num_materials) {
  if (field.param_dim() != 3)
    throw Error(
        fmt::format("a material field must be a trivariate (3 parametric directions), "
                    "got {} direction(s)",
                    field.param_dim()));
  if (field.point_dim() > kMaxMaterials)
    throw Error(fmt::format("a material field has at most {} components, got {}", kMaxMaterials, field.point_dim()));
  if (static_cast<int>(component_material.size()) != field.point_dim())
    throw Error(
        fmt::format("the material field has {} component(s) but {} material(s) are "
                    "assigned to them",
                    field.point_dim(), component_material.size()));
  std::vector<bool> used(static_cast<std::size_t>(num_materials), false);
  for (std::size_t c = 0; c < component_material.size(); ++c) {
    const int j = component_material[c];
    if (j == kVoidMaterial) continue;
    if (j < 0 || j >= num_materials)
      throw Error(fmt::format("component {} names material index {}, outside [0, {})", c, j, num_materials));
    if (used[static_cast<std::size_t>(j)])
      throw Error(fmt::format("component {} names material index {} a second time", c, j));
    used[static_cast<std::size_t>(j)] = true;
  }
}

}  // namespace

SplineFieldMaterial::SplineFieldMaterial(TensorSpline field, std::vector<int> component_material, int num_materials,
                                         const ParamBox& cell_domain)
    : MaterialFunction(num_materials), field_(std::move(field)), component_material_(std::move(component_material)) {
  validate_field(field_, component_material_, num_materials);
  map_ = AffineParamMap::between(cell_domain, spline_domain(field_));
}

void SplineFieldMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                       std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const std::size_t k = component_material_.size();
  std::array<double, kMaxMaterials> value{};
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    const std::array<double, 3> t{p.x, p.y, p.z};
    field_.evaluate(t, value);
    float* f = fractions.data() + s * m;
    std::fill(f, f + m, 0.0f);
    for (std::size_t c = 0; c < k; ++c) {
      const int j = component_material_[c];
      if (j != kVoidMaterial) f[j] = static_cast<float>(value[c]);
    }
  }
}

void SplineFieldMaterial::bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const {
  std::array<double, kMaxMaterials> clo{}, chi{};
  detail::coefficient_bounds(field_, map_(box), clo, chi);
  const auto m = static_cast<std::size_t>(num_materials());
  std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  std::fill(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  for (std::size_t c = 0; c < component_material_.size(); ++c) {
    const int j = component_material_[c];
    if (j == kVoidMaterial) continue;
    // Round outwards so that the float bounds still contain the double values.
    lo[static_cast<std::size_t>(j)] = std::nextafter(static_cast<float>(clo[c]), -1e30f);
    hi[static_cast<std::size_t>(j)] = std::nextafter(static_cast<float>(chi[c]), 1e30f);
  }
}

FractionEnclosure SplineFieldMaterial::enclose(const ParamBox& box, const Box3&) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const std::size_t k = component_material_.size();
  const TensorSpline piece = detail::restricted_piece(field_, map_(box));
  const ParamBox whole{{piece.lo(0), piece.lo(1), piece.lo(2)}, {piece.hi(0), piece.hi(1), piece.hi(2)}};
  std::array<double, kMaxMaterials> clo{}, chi{}, weights{};
  detail::coefficient_bounds(piece, whole, clo, chi);
  FractionEnclosure e;
  e.fractions.assign(m, Interval::point(0.0));
  for (std::size_t c = 0; c < k; ++c) {
    const int j = component_material_[c];
    if (j == kVoidMaterial) continue;
    e.fractions[static_cast<std::size_t>(j)] = {clo[c], chi[c]};
    weights[c] = 1.0;
  }
  detail::coefficient_sum_bounds(piece, whole, std::span<const double>(weights.data(), k), e.sum.lo, e.sum.hi);
  // De Boor's evaluation in double stays within the hull but for its rounding.
  for (Interval& f : e.fractions) f = {f.lo - std::abs(f.lo) * 1e-12, f.hi + std::abs(f.hi) * 1e-12};
  e.sum = {e.sum.lo - std::abs(e.sum.lo) * 1e-12 - 1e-300, e.sum.hi + std::abs(e.sum.hi) * 1e-12 + 1e-300};
  return e;
}

}  // namespace trivox
