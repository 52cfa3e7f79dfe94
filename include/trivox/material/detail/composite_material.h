// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Composition of material functions: new functions built from others, so that textures,
// fields, expressions and procedural kinds combine without new code for each pairing.
//
// A *scalar source* here is any material function with one output (num_materials() == 1):
// its single fraction is read as a number, not checked as a fraction (a constant, an
// expression, a component or the magnitude of a spline field (field_scalar_material.h), one
// channel of a texture). Every part is built
// for the same cell and receives the same (u,v,w) and (x,y,z); parts are evaluated over the
// whole row, then combined per sample.
//
// Rules (s a scalar source's value at the sample):
//  * blend:     (1 - t) a + t b, with t = s clamped to [0, 1];
//  * threshold: below where s < level, above where s >= level (NaN: below);
//  * select:    the function of the first region whose box holds the sample's normalised
//               parameters (boxes closed, in the cell's domain mapped onto [0,1]^3), else
//               `otherwise`;
//  * void mask: material scaled by 1 - t, t = s clamped to [0, 1]: t = 1 is empty (void),
//               t = 0 leaves the material as it is (porosity as a field).
//  * transfer:  the fractions of `stops` (scalar_gradient_material.h) at value s: a transfer
//               function from any scalar source to materials.
#pragma once

#include <memory>
#include <vector>

#include "trivox/material/detail/scalar_gradient_material.h"
#include "trivox/material/material_function.h"

namespace trivox {

using MaterialPtr = std::shared_ptr<const MaterialFunction>;

class BlendMaterial final : public MaterialFunction {
 public:
  // a and b: the same material count; weight: a scalar source. Throws Error otherwise.
  BlendMaterial(MaterialPtr a, MaterialPtr b, MaterialPtr weight);
  std::string_view kind() const noexcept override { return "blend"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  MaterialPtr a_, b_, weight_;
};

class ThresholdMaterial final : public MaterialFunction {
 public:
  // below and above: the same material count; source: a scalar source; level finite.
  ThresholdMaterial(MaterialPtr source, double level, MaterialPtr below, MaterialPtr above);
  std::string_view kind() const noexcept override { return "threshold"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  MaterialPtr source_;
  double level_;
  MaterialPtr below_, above_;
};

struct SelectRegion {
  ParamBox box;  // in normalised parameters, lo <= hi in each direction
  MaterialPtr material;
};

class SelectMaterial final : public MaterialFunction {
 public:
  // Every region's material and `otherwise`: the same material count. Throws Error otherwise
  // or when a box is empty or not finite.
  SelectMaterial(std::vector<SelectRegion> regions, MaterialPtr otherwise, const ParamBox& cell_domain);
  std::string_view kind() const noexcept override { return "select"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  std::vector<SelectRegion> regions_;
  MaterialPtr otherwise_;
  AffineParamMap map_;
};

class VoidMaskMaterial final : public MaterialFunction {
 public:
  VoidMaskMaterial(MaterialPtr material, MaterialPtr void_share);
  std::string_view kind() const noexcept override { return "void_mask"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  MaterialPtr material_, void_share_;
};

class TransferMaterial final : public MaterialFunction {
 public:
  // stops: as for ScalarGradientMaterial (at least one, values finite and non-decreasing,
  // the same number of finite fractions each). Throws Error naming the rule.
  TransferMaterial(MaterialPtr source, std::vector<GradientStop> stops);
  std::string_view kind() const noexcept override { return "transfer"; }
  void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const override;
  FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const override;

 private:
  MaterialPtr source_;
  std::vector<GradientStop> stops_;
};

}  // namespace trivox
