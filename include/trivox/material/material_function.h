// Material functions M(u,v,w): what a cell of an FGM object is made of at each parameter.
//
// A material function returns, per sample, one fraction per material of the scene, indexed
// 0..m-1 in the scene's material list. Void (no material) is implicit: 1 - sum. After the
// scene's fraction policy (see CheckedMaterial below) every fraction is >= 0 and the sum of
// one sample's fractions is <= 1 (up to float rounding).
//
// Parameters: a material function is built for one cell and receives that cell's own
// parameters (u,v,w) in its parametric domain, plus the model-space position (x,y,z) in mm
// of the same point. Each kind maps the cell's domain affinely onto its reference domain
// (a spline field onto the field's own domain, the procedural kinds onto [0,1]^3), so the
// same definition drives cells whose domains differ (paper, Section 4: textures are reused
// across V-reps like 2D textures across surfaces).
//
// Evaluation is per row: one virtual call evaluates n samples (a run of voxels of a slice),
// so dispatch never happens per voxel. Every evaluator is const and safe to call
// concurrently from several threads on the same object.
#pragma once

#include "trivox/limits.h"

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/error.h"
#include "trivox/material/fraction_enclosure.h"
#include "trivox/math.h"

namespace trivox {

// A material index meaning "no material" wherever a material function names one material
// (a porous tile's colour, a curve's colour, a background).
inline constexpr int kVoidMaterial = -1;

// The affine map that sends the box `from` onto the box `to`, direction by direction:
// p -> to.lo + (p - from.lo) * (to.hi - to.lo) / (from.hi - from.lo).
struct AffineParamMap {
  Vec3 scale{1.0, 1.0, 1.0};
  Vec3 offset{0.0, 0.0, 0.0};

  // Both boxes must have a positive extent in every direction (a spline's domain always has).
  static AffineParamMap between(const ParamBox& from, const ParamBox& to) noexcept;

  Vec3 operator()(Vec3 p) const noexcept {
    return {offset.x + scale.x * p.x, offset.y + scale.y * p.y, offset.z + scale.z * p.z};
  }
  // The image of a box (the scales are positive, so corners map to corners).
  ParamBox operator()(const ParamBox& b) const noexcept { return {(*this)(b.lo), (*this)(b.hi)}; }
};

// The unit cube [0,1]^3, the reference domain of the procedural and expression kinds.
inline constexpr ParamBox kUnitParamBox{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};

class MaterialFunction {
 public:
  virtual ~MaterialFunction() = default;
  MaterialFunction(const MaterialFunction&) = delete;
  MaterialFunction& operator=(const MaterialFunction&) = delete;

  // m: how many fractions one sample has (the scene's material count).
  int num_materials() const noexcept { return num_materials_; }

  // A short name of the kind ("constant", "spline_field", ...), for reports and errors.
  virtual std::string_view kind() const noexcept = 0;

  // Evaluates n = uvw.size() samples. uvw: the cell's parameters; xyz: the model-space
  // positions (mm) of the same points, xyz.size() == n; fractions: n * m values written
  // sample-major, fractions[s * m + j] = fraction of material j at sample s. Parameters
  // outside the cell's domain are clamped to it. Throws only where stated by the kind or
  // by CheckedMaterial.
  virtual void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> fractions) const = 0;

  // Conservative bounds over a box of the cell's parameters (and any position): for every
  // p in `box` and every material j, lo[j] <= M_j(p) <= hi[j]. lo and hi hold m values each.
  // A kind that cannot bound itself reports [-inf, +inf]; this default does so.
  virtual void bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const;

  // An enclosure of the fractions and of their sum over a box of the cell's parameters,
  // for the samples whose positions lie in `xyz` (mm; a box that holds the cell's image of
  // `box`): sound (every value evaluate_row computes there, before its rounding to float,
  // lies inside), possibly loose. fraction_check.h proves a scene's fraction rules with it.
  // This default derives it from bounds() and sums the fraction intervals; kinds that know
  // more (a constant exactly, spline fields by their coefficients, expressions by interval
  // arithmetic with the mean-value form) override it.
  virtual FractionEnclosure enclose(const ParamBox& box, const Box3& xyz) const;

  // One sample: a convenience for tests and tools, not for the slicing loop.
  void evaluate(Vec3 uvw, Vec3 xyz, std::span<float> fractions) const {
    evaluate_row(std::span<const Vec3>(&uvw, 1), std::span<const Vec3>(&xyz, 1), fractions);
  }

 protected:
  // Throws Error unless 1 <= num_materials <= kMaxMaterials.
  explicit MaterialFunction(int num_materials);

 private:
  int num_materials_;
};

// What to do when a sample's fractions break the rules (a negative fraction or a sum above 1).
enum class SumPolicy {
  kError,      // beyond `tolerance`: throw InputError naming the cell and (u,v,w)
  kNormalise,  // clamp negatives to 0, scale sums above 1 down to 1
};

struct FractionPolicy {
  SumPolicy policy = SumPolicy::kError;
  // Slack allowed on both rules before the "error" policy throws; within it, fractions are
  // still clamped and scaled so that the output rules hold exactly. Dimensionless.
  double tolerance = 1e-4;

  // Throws Error unless tolerance is finite and in [0, 1).
  void validate() const;
};

// Where a material function was defined, for the error the "error" policy throws:
// InputError(source, 0, pointer, "cell '<cell>': <rule> at (u,v,w) = (...)").
struct MaterialSite {
  std::string source;                       // the scene file
  std::string pointer;                      // JSON pointer of the cell's material, e.g. "/cells/2/material"
  std::string cell;                         // the cell's name
  std::vector<std::string> material_names;  // names by index for messages (may be empty)
};

// What the fraction policy throws: an InputError at the scene file and the JSON pointer of
// the cell's material, whose message names the cell, the rule and where: the parameters and
// the position in mm (6 significant digits each), and the layer once the slicer adds it,
// e.g. "cell 'lid': layer 124 (z = 3.705 mm): the fractions sum to 1.3 > 1 (...) at (u,v,w) =
// (0.5, 0.25, 1), (x,y,z) = (20.5, 3.25, 3.705) mm".
class FractionError : public InputError {
 public:
  FractionError(const MaterialSite& site, std::string rule, Vec3 uvw, const Vec3* xyz);

  const std::string& cell() const noexcept { return cell_; }
  const std::string& broken_rule() const noexcept { return broken_rule_; }  // the rule alone
  Vec3 uvw() const noexcept { return uvw_; }
  bool has_position() const noexcept { return has_xyz_; }
  Vec3 xyz() const noexcept { return xyz_; }
  int layer() const noexcept { return layer_; }  // 1-based; 0 when not known

  // The same error, met in layer `layer` (1-based, as in the file names) at height z_mm.
  FractionError in_layer(int layer, double z_mm) const;

 private:
  FractionError(std::string file, std::string where, std::string message);
  std::string cell_, broken_rule_, source_, pointer_;
  Vec3 uvw_{}, xyz_{};
  bool has_xyz_ = false;
  int layer_ = 0;
};

// Applies `policy` in place to n samples of m fractions (n = uvw.size(), the parameters
// reported in errors; xyz, when not empty, the positions, reported too). A fraction that is
// not a finite number is an error under both policies. Allocation-free; throws FractionError.
void apply_fraction_policy(const FractionPolicy& policy, const MaterialSite& site, int m, std::span<const Vec3> uvw,
                           std::span<float> fractions, std::span<const Vec3> xyz = {});

}  // namespace trivox
