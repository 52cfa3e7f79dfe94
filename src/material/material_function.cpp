#include "trivox/material/material_function.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

AffineParamMap AffineParamMap::between(const ParamBox& from, const ParamBox& to) noexcept {
  AffineParamMap map;
  for (int d = 0; d < 3; ++d) {
    map.scale[d] = (to.hi[d] - to.lo[d]) / (from.hi[d] - from.lo[d]);
    map.offset[d] = to.lo[d] - map.scale[d] * from.lo[d];
  }
  return map;
}

MaterialFunction::MaterialFunction(int num_materials) : num_materials_(num_materials) {
  if (num_materials < 1 || num_materials > kMaxMaterials)
    throw Error(fmt::format("a material function needs 1 to {} materials, got {}", kMaxMaterials, num_materials));
}

void MaterialFunction::bounds(const ParamBox&, std::span<float> lo, std::span<float> hi) const {
  for (std::size_t j = 0; j < static_cast<std::size_t>(num_materials_); ++j) {
    lo[j] = -std::numeric_limits<float>::infinity();
    hi[j] = std::numeric_limits<float>::infinity();
  }
}

FractionEnclosure FractionEnclosure::unknown(int num_materials) {
  FractionEnclosure e;
  e.fractions.assign(static_cast<std::size_t>(num_materials), Interval::everything());
  e.sum = Interval::everything();
  e.finite = false;
  return e;
}

FractionEnclosure MaterialFunction::enclose(const ParamBox& box, const Box3&) const {
  const auto m = static_cast<std::size_t>(num_materials_);
  std::vector<float> lo(m), hi(m);
  bounds(box, lo, hi);
  FractionEnclosure e;
  e.finite = true;
  e.sum = {0.0, 0.0};
  for (std::size_t j = 0; j < m; ++j) {
    e.fractions.push_back({lo[j], hi[j]});
    e.finite = e.finite && std::isfinite(lo[j]) && std::isfinite(hi[j]);
    e.sum.lo += lo[j];
    e.sum.hi += hi[j];
  }
  // The sum of m doubles rounded outwards by a relative margin far above its error.
  e.sum.lo -= std::abs(e.sum.lo) * 1e-12;
  e.sum.hi += std::abs(e.sum.hi) * 1e-12;
  if (!e.finite) e.sum = Interval::everything();
  return e;
}

void FractionPolicy::validate() const {
  if (!std::isfinite(tolerance) || tolerance < 0.0 || tolerance >= 1.0)
    throw Error(fmt::format("fraction tolerance {} is not a finite value in [0, 1)", tolerance));
}

namespace {

std::string material_label(const MaterialSite& site, int j) {
  const auto index = static_cast<std::size_t>(j);
  return index < site.material_names.size() ? fmt::format("'{}'", site.material_names[index]) : fmt::format("{}", j);
}

std::string where_text(Vec3 p, const Vec3* xyz) {
  std::string text = fmt::format("(u,v,w) = ({:.6g}, {:.6g}, {:.6g})", p.x, p.y, p.z);
  if (xyz) text += fmt::format(", (x,y,z) = ({:.6g}, {:.6g}, {:.6g}) mm", xyz->x, xyz->y, xyz->z);
  return text;
}

// Kept out of line so that the row loop stays small; it only runs on the way to an error.
[[noreturn]] void fail(const MaterialSite& site, std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::size_t s,
                       const std::string& rule) {
  throw FractionError(site, rule, uvw[s], s < xyz.size() ? &xyz[s] : nullptr);
}

}  // namespace

namespace {

// Whether the policy leaves every sample as it is: each fraction finite and >= 0, each
// sample's sum (added in double, as the policy adds it) <= 1. Branch-free so that the
// compiler vectorizes it; most material functions give such rows, and then the policy costs
// one pass. kM = 0: any count, m.
template <std::size_t kM>
bool row_untouched(const float* f, std::size_t samples, std::size_t m) noexcept {
  const std::size_t n = kM > 0 ? kM : m;
  int ok = 1;
  for (std::size_t i = 0; i < samples * n; ++i)
    ok &= static_cast<int>(f[i] >= 0.0f) & static_cast<int>(f[i] <= std::numeric_limits<float>::max());
  for (std::size_t s = 0; s < samples; ++s) {
    double sum = 0.0;
    for (std::size_t j = 0; j < n; ++j) sum += f[s * n + j];
    ok &= static_cast<int>(sum <= 1.0);
  }
  return ok != 0;
}

}  // namespace

FractionError::FractionError(const MaterialSite& site, std::string rule, Vec3 uvw, const Vec3* xyz)
    : InputError(site.source, 0, site.pointer,
                 fmt::format("cell '{}': {} at {}", site.cell, rule, where_text(uvw, xyz))),
      cell_(site.cell),
      broken_rule_(std::move(rule)),
      source_(site.source),
      pointer_(site.pointer),
      uvw_(uvw),
      xyz_(xyz ? *xyz : Vec3{}),
      has_xyz_(xyz != nullptr) {}

FractionError::FractionError(std::string file, std::string where, std::string message)
    : InputError(std::move(file), 0, std::move(where), std::move(message)) {}

FractionError FractionError::in_layer(int layer, double z_mm) const {
  FractionError e(source_, pointer_,
                  fmt::format("cell '{}': layer {} (z = {:.6g} mm): {} at {}", cell_, layer, z_mm, broken_rule_,
                              where_text(uvw_, has_xyz_ ? &xyz_ : nullptr)));
  e.cell_ = cell_;
  e.broken_rule_ = broken_rule_;
  e.source_ = source_;
  e.pointer_ = pointer_;
  e.uvw_ = uvw_;
  e.xyz_ = xyz_;
  e.has_xyz_ = has_xyz_;
  e.layer_ = layer;
  return e;
}

void apply_fraction_policy(const FractionPolicy& policy, const MaterialSite& site, int m, std::span<const Vec3> uvw,
                           std::span<float> fractions, std::span<const Vec3> xyz) {
  const auto count = static_cast<std::size_t>(m);
  const bool untouched = count == 1   ? row_untouched<1>(fractions.data(), uvw.size(), 1)
                         : count == 2 ? row_untouched<2>(fractions.data(), uvw.size(), 2)
                         : count == 3 ? row_untouched<3>(fractions.data(), uvw.size(), 3)
                                      : row_untouched<0>(fractions.data(), uvw.size(), count);
  if (untouched) return;
  const bool strict = policy.policy == SumPolicy::kError;
  const double tol = policy.tolerance;
  const auto mm = static_cast<std::size_t>(m);
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    float* f = fractions.data() + s * mm;
    double sum = 0.0;
    for (std::size_t j = 0; j < mm; ++j) {
      const float v = f[j];
      if (!std::isfinite(v))
        fail(site, uvw, xyz, s,
             fmt::format("the fraction of material {} is {}, not a finite number",
                         material_label(site, static_cast<int>(j)), v));
      if (v < 0.0f) {
        if (strict && v < -tol)
          fail(site, uvw, xyz, s,
               fmt::format("the fraction of material {} is {:.6g} < 0 (tolerance {}; the scene's "
                           "fraction policy is \"error\")",
                           material_label(site, static_cast<int>(j)), v, tol));
        f[j] = 0.0f;
      } else {
        sum += v;
      }
    }
    if (sum > 1.0) {
      if (strict && sum > 1.0 + tol)
        fail(site, uvw, xyz, s,
             fmt::format("the fractions sum to {:.6g} > 1 (tolerance {}; the scene's fraction "
                         "policy is \"error\", \"normalise\" would scale them down)",
                         sum, tol));
      const auto scale = static_cast<float>(1.0 / sum);
      for (std::size_t j = 0; j < mm; ++j) f[j] *= scale;
    }
  }
}

}  // namespace trivox
