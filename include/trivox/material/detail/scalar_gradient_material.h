// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// ScalarGradientMaterial: a scalar trivariate field s(u,v,w) (point dimension 1, e.g. an
// IRIT `E1` trivariate) mapped through a piecewise-linear gradient of materials, like a
// colour ramp: between two stops the fractions are interpolated linearly in s; below the
// first stop and above the last the end stops hold. Two stops at the same value make a
// step; at that value the later stop applies.
//
// Domain: the cell's parameters are mapped affinely onto the field's domain (as for
// SplineFieldMaterial).
#pragma once

#include <span>
#include <vector>

#include "trivox/material/material_function.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox {

struct GradientStop {
  double value = 0.0;            // field value, in the field's own units
  std::vector<float> fractions;  // one per material
};

// Throws Error naming the stop unless there is at least one stop, values are finite and
// non-decreasing, and every stop has as many finite fractions as the first.
void validate_gradient_stops(const std::vector<GradientStop>& stops);

// The ramp of `stops` (non-decreasing values, m fractions each) at value s: writes m
// fractions to out. NaN in gives NaN out (for the fraction policy to report).
void gradient_ramp(std::span<const GradientStop> stops, double s, std::span<float> out) noexcept;

class ScalarGradientMaterial final : public MaterialFunction {
 public:
  // field: param_dim 3, point_dim 1. stops: at least one, values finite and non-decreasing,
  // every stop with the same number m of finite fractions. Throws Error naming the rule.
  ScalarGradientMaterial(TensorSpline field, std::vector<GradientStop> stops, const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "scalar_gradient"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // Bounds the field by its control coefficients, then the ramp over that value interval.
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;
  // The ramp over the field's coefficient bounds on the box (the restricted piece).
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

  const TensorSpline& field() const noexcept { return field_; }
  const std::vector<GradientStop>& stops() const noexcept { return stops_; }

  // The ramp alone: writes the m fractions at field value s.
  void ramp(double s, std::span<float> out) const noexcept;

 private:
  TensorSpline field_;
  std::vector<GradientStop> stops_;
  AffineParamMap map_;
};

}  // namespace trivox
