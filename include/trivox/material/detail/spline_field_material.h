// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// SplineFieldMaterial: M(u,v,w) given by a trivariate B-spline or NURBS with k components
// (any orders, its own knots; e.g. a refinement of the cell's spline space, as in the
// paper's Section 3). Component c is the fraction of material component_material[c].
//
// Domain: the cell's parameters are mapped affinely onto the field's domain, direction by
// direction, so a field on [0,1]^3 drives a cell whose domain is, say, [0,13]^3. When the
// two domains coincide (a refinement of V's space) the map is the identity.
#pragma once

#include <vector>

#include "trivox/material/material_function.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

class SplineFieldMaterial final : public MaterialFunction {
 public:
  // field: param_dim 3, point_dim k in [1, kMaxMaterials]. component_material: k entries,
  // each a material index in [0, num_materials) or kVoidMaterial (a component that stores
  // the void fraction, ignored); no material twice. Throws Error naming the rule.
  SplineFieldMaterial(TensorSpline field, std::vector<int> component_material, int num_materials,
                      const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "spline_field"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // Minimum and maximum control coefficients whose basis support meets the box (convex
  // hull property; NURBS weights are positive).
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;
  // Per component and for the sum of the components: the control coefficients of the
  // field restricted to the box (the tight hull of that piece).
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

  const TensorSpline& field() const noexcept { return field_; }
  const AffineParamMap& cell_to_field() const noexcept { return map_; }

 private:
  TensorSpline field_;
  std::vector<int> component_material_;
  AffineParamMap map_;
};

}  // namespace trivox
