#include "trivox/material/detail/constant_material.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

ConstantMaterial::ConstantMaterial(std::vector<float> fractions)
    : MaterialFunction(static_cast<int>(fractions.size())), fractions_(std::move(fractions)) {
  for (std::size_t j = 0; j < fractions_.size(); ++j)
    if (!std::isfinite(fractions_[j]))
      throw Error(fmt::format("constant material: fraction {} is {}, not a finite number", j, fractions_[j]));
}

void ConstantMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                    std::span<float> fractions) const {
  const std::size_t m = fractions_.size();
  for (std::size_t s = 0; s < uvw.size(); ++s)
    std::copy(fractions_.begin(), fractions_.end(), fractions.begin() + static_cast<std::ptrdiff_t>(s * m));
}

void ConstantMaterial::bounds(const ParamBox&, std::span<float> lo, std::span<float> hi) const {
  std::copy(fractions_.begin(), fractions_.end(), lo.begin());
  std::copy(fractions_.begin(), fractions_.end(), hi.begin());
}

}  // namespace trivox
