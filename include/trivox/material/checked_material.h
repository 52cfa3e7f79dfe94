// CheckedMaterial: a material function with the scene's fraction policy applied to its
// output, so that whoever evaluates a cell always gets fractions that obey the rules of
// material_function.h (each >= 0, sum <= 1) or an InputError that names the scene file,
// the JSON pointer of the cell's material, the cell and the offending (u,v,w).
#pragma once

#include <memory>

#include "trivox/material/material_function.h"

namespace trivox {

class CheckedMaterial final : public MaterialFunction {
 public:
  // Throws Error when `inner` is null or the policy is invalid.
  CheckedMaterial(std::shared_ptr<const MaterialFunction> inner, FractionPolicy policy, MaterialSite site);

  std::string_view kind() const noexcept override { return inner_->kind(); }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // The inner bounds, clamped to [0, 1]; lower bounds drop to 0 where a sum could exceed 1
  // (scaling down could lower any fraction).
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;

  const MaterialFunction& inner() const noexcept { return *inner_; }
  const FractionPolicy& policy() const noexcept { return policy_; }
  const MaterialSite& site() const noexcept { return site_; }

 private:
  std::shared_ptr<const MaterialFunction> inner_;
  FractionPolicy policy_;
  MaterialSite site_;
};

}  // namespace trivox
