// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// TwistingCurvesMaterial: the chalice's twisting coloured curves (paper, Section 4). In every
// plane w = const of the cell's parametric domain (mapped onto [0,1]^3) a few points carry
// colours; with w the points turn about a centre and/or shift. A sample whose (u,v) lies
// within `radius` of a point takes that point's material (the nearest point when several
// qualify), every other sample the background material (the paper's transparent one).
//
// The point that starts at p0 = (u0, v0) sits at
//   c + R(2 pi turns_per_w w) (p0 - c) + w (shift_u_per_w, shift_v_per_w)
// where R(a) turns counter-clockwise (from +u towards +v). Distances are Euclidean in the
// (u,v) unit square; with wrap_u (wrap_v) they are periodic with period 1 along u (v), for
// cells whose u (v) direction closes on itself.
#pragma once

#include <array>
#include <vector>

#include "trivox/material/material_function.h"

namespace trivox {

struct TwistingCurvesParams {
  struct Point {
    double u = 0.5, v = 0.5;  // position at w = 0, in [0,1]^2 units
    int material = 0;         // material index or kVoidMaterial
  };
  std::vector<Point> points;  // at least one
  double radius = 0.05;       // (u,v) distance, unit-square units, > 0
  double centre_u = 0.5, centre_v = 0.5;
  double turns_per_w = 0.0;  // full turns per unit of w
  double shift_u_per_w = 0.0, shift_v_per_w = 0.0;
  bool wrap_u = false, wrap_v = false;
  int background = kVoidMaterial;  // material index or kVoidMaterial

  // Throws Error naming the field and the rule.
  void validate(int num_materials) const;
};

class TwistingCurvesMaterial final : public MaterialFunction {
 public:
  TwistingCurvesMaterial(TwistingCurvesParams params, int num_materials, const ParamBox& cell_domain);

  std::string_view kind() const noexcept override { return "twisting_curves"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  // [0, 1] for the materials of the points and the background, 0 for the others.
  void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const override;
  // Every sample is one material or void: the sum is at most the largest upper bound.
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

  const TwistingCurvesParams& params() const noexcept { return params_; }

  // Where point `index` sits at normalised height w (unit-square units, before wrapping).
  std::array<double, 2> point_at(int index, double w) const noexcept;

 private:
  TwistingCurvesParams params_;
  AffineParamMap map_;  // cell parameters -> [0,1]^3
};

}  // namespace trivox
