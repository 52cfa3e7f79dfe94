#include "trivox/material/field_scalar_material.h"

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

}  // namespace trivox
