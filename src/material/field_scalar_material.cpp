#include "trivox/material/detail/field_scalar_material.h"

#include "material/spline_coefficient_bounds.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

FieldScalarMaterial::FieldScalarMaterial(TensorSpline field, FieldScalarChoice choice, const ParamBox& cell_domain)
    : MaterialFunction(1), field_(std::move(field)), choice_(choice) {
  if (field_.param_dim() != 3)
    throw Error(fmt::format("a scalar field source must be a trivariate (3 parametric directions), got {}",
                            field_.param_dim()));
  if (field_.point_dim() < 1 || field_.point_dim() > kMaxMaterials)
    throw Error(fmt::format("a scalar field source has 1 to {} components, got {}", kMaxMaterials, field_.point_dim()));
  if (!choice_.magnitude && (choice_.component < 0 || choice_.component >= field_.point_dim()))
    throw Error(
        fmt::format("component {} is not one of the field's {} components", choice_.component, field_.point_dim()));
  const ParamBox domain{{field_.lo(0), field_.lo(1), field_.lo(2)}, {field_.hi(0), field_.hi(1), field_.hi(2)}};
  map_ = AffineParamMap::between(cell_domain, domain);
}

void FieldScalarMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                       std::span<float> values) const {
  const auto k = static_cast<std::size_t>(field_.point_dim());
  std::array<double, kMaxMaterials> v{};
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    // Parameters outside the domain are clamped to it, as for every material function.
    const std::array<double, 3> t{std::clamp(p.x, field_.lo(0), field_.hi(0)),
                                  std::clamp(p.y, field_.lo(1), field_.hi(1)),
                                  std::clamp(p.z, field_.lo(2), field_.hi(2))};
    field_.evaluate(t, std::span<double>(v.data(), k));
    if (choice_.magnitude) {
      double sum = 0.0;
      for (std::size_t c = 0; c < k; ++c) sum += v[c] * v[c];
      values[s] = static_cast<float>(std::sqrt(sum));
    } else {
      values[s] = static_cast<float>(v[static_cast<std::size_t>(choice_.component)]);
    }
  }
}

FractionEnclosure FieldScalarMaterial::enclose(const ParamBox& box, const Box3&) const {
  const TensorSpline piece = detail::restricted_piece(field_, map_(box));
  const ParamBox whole{{piece.lo(0), piece.lo(1), piece.lo(2)}, {piece.hi(0), piece.hi(1), piece.hi(2)}};
  const auto k = static_cast<std::size_t>(field_.point_dim());
  std::array<double, kMaxMaterials> lo{}, hi{};
  detail::coefficient_bounds(piece, whole, std::span<double>(lo.data(), k), std::span<double>(hi.data(), k));
  Interval value;
  if (choice_.magnitude) {
    // sqrt of the sum of squares, each square from its component's interval.
    double sq_lo = 0.0, sq_hi = 0.0;
    for (std::size_t c = 0; c < k; ++c) {
      const double a = std::abs(lo[c]), b = std::abs(hi[c]);
      sq_lo += lo[c] <= 0.0 && hi[c] >= 0.0 ? 0.0 : std::min(a, b) * std::min(a, b);
      sq_hi += std::max(a, b) * std::max(a, b);
    }
    value = {std::sqrt(sq_lo) * (1 - 1e-12), std::sqrt(sq_hi) * (1 + 1e-12) + 1e-300};
  } else {
    const auto c = static_cast<std::size_t>(choice_.component);
    value = {lo[c] - std::abs(lo[c]) * 1e-12, hi[c] + std::abs(hi[c]) * 1e-12};
  }
  FractionEnclosure e;
  e.fractions = {value};
  e.sum = value;
  e.finite = std::isfinite(value.lo) && std::isfinite(value.hi);
  return e;
}

}  // namespace trivox
