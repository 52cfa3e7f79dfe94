// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// A scalar source from a spline field (an analysis result such as a stress or temperature
// trivariate): one of its components, or the Euclidean length of its vector of components.
// It has one output (num_materials() == 1), read as a number by the compositions of
// composite_material.h (a transfer function, a blend weight, ...), not as a fraction.
//
// Domain: the cell's parameters map affinely onto the field's own domain, as for
// SplineFieldMaterial.
#pragma once

#include "trivox/material/material_function.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct FieldScalarChoice {
  // The component read, 0 .. point_dim - 1; ignored when `magnitude` is set.
  int component = 0;
  // The length sqrt(sum of squares) of all components instead of one.
  bool magnitude = false;
};

class FieldScalarMaterial final : public MaterialFunction {
 public:
  // field: a trivariate with 1 .. 64 components; the component must exist. Throws Error
  // naming the rule.
  FieldScalarMaterial(TensorSpline field, FieldScalarChoice choice, const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "field_scalar"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> values) const override;
  // The component's (or the magnitude's) bounds from the field restricted to the box.
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  TensorSpline field_;
  FieldScalarChoice choice_;
  AffineParamMap map_;
};

}  // namespace trivox
