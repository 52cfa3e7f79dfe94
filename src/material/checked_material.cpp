#include "trivox/material/checked_material.h"

#include <algorithm>

#include "trivox/error.h"

namespace trivox {

namespace {
int checked_count(const std::shared_ptr<const MaterialFunction>& inner) {
  if (!inner) throw Error("CheckedMaterial needs a material function, got none");
  return inner->num_materials();
}
}  // namespace

CheckedMaterial::CheckedMaterial(std::shared_ptr<const MaterialFunction> inner, FractionPolicy policy,
                                 MaterialSite site)
    : MaterialFunction(checked_count(inner)), inner_(std::move(inner)), policy_(policy), site_(std::move(site)) {
  policy_.validate();
}

void CheckedMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                   std::span<float> fractions) const {
  inner_->evaluate_row(uvw, xyz, fractions);
  apply_fraction_policy(policy_, site_, num_materials(), uvw, fractions, xyz);
}

void CheckedMaterial::bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const {
  inner_->bounds(box, lo, hi);
  const auto m = static_cast<std::size_t>(num_materials());
  double hi_sum = 0.0;
  for (std::size_t j = 0; j < m; ++j) {
    lo[j] = std::clamp(lo[j], 0.0f, 1.0f);
    hi[j] = std::clamp(hi[j], 0.0f, 1.0f);
    hi_sum += hi[j];
  }
  if (hi_sum > 1.0) std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
}

}  // namespace trivox
