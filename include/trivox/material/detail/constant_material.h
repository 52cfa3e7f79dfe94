// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// ConstantMaterial: the same fractions everywhere in the cell.
#pragma once

#include <vector>

#include "trivox/material/material_function.h"

namespace trivox {

class ConstantMaterial final : public MaterialFunction {
 public:
  // One fraction per material (fractions.size() = m). Throws Error when a value is not
  // finite or the size is out of range; sums are the fraction policy's business.
  explicit ConstantMaterial(std::vector<float> fractions);

  std::string_view kind() const noexcept override { return "constant"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;

  const std::vector<float>& fractions() const noexcept { return fractions_; }

 private:
  std::vector<float> fractions_;
};

}  // namespace trivox
