#include "trivox/material/detail/twisting_curves_material.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

namespace {

void require_finite(const char* field, double value) {
  if (!std::isfinite(value)) throw Error(fmt::format("twisting curves: {} = {} is not a finite number", field, value));
}

bool valid_material(int j, int num_materials) { return j == kVoidMaterial || (j >= 0 && j < num_materials); }

}  // namespace

void TwistingCurvesParams::validate(int num_materials) const {
  if (points.empty()) throw Error("twisting curves: there must be at least one point");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i].u) || !std::isfinite(points[i].v))
      throw Error(fmt::format("twisting curves: point {} has a coordinate that is not finite", i));
    if (!valid_material(points[i].material, num_materials))
      throw Error(
          fmt::format("twisting curves: point {} has material index {}, not in [0, {}) "
                      "nor void",
                      i, points[i].material, num_materials));
  }
  require_finite("radius", radius);
  if (!(radius > 0.0)) throw Error(fmt::format("twisting curves: radius {} is not > 0", radius));
  require_finite("centre_u", centre_u);
  require_finite("centre_v", centre_v);
  require_finite("turns_per_w", turns_per_w);
  require_finite("shift_u_per_w", shift_u_per_w);
  require_finite("shift_v_per_w", shift_v_per_w);
  if (!valid_material(background, num_materials))
    throw Error(
        fmt::format("twisting curves: background material index {} is not in [0, {}) "
                    "nor void",
                    background, num_materials));
}

TwistingCurvesMaterial::TwistingCurvesMaterial(TwistingCurvesParams params, int num_materials,
                                               const ParamBox& cell_domain)
    : MaterialFunction(num_materials),
      params_(std::move(params)),
      map_(AffineParamMap::between(cell_domain, kUnitParamBox)) {
  params_.validate(num_materials);
}

namespace {

// The rotation and shift of the points at normalised height w.
struct Motion {
  double c, s, shift_u, shift_v;
  Motion(const TwistingCurvesParams& params, double w) noexcept
      : c(std::cos(2.0 * std::numbers::pi * params.turns_per_w * w)),
        s(std::sin(2.0 * std::numbers::pi * params.turns_per_w * w)),
        shift_u(params.shift_u_per_w * w),
        shift_v(params.shift_v_per_w * w) {}
  std::array<double, 2> apply(const TwistingCurvesParams& params, const TwistingCurvesParams::Point& p) const noexcept {
    const double du = p.u - params.centre_u, dv = p.v - params.centre_v;
    return {params.centre_u + c * du - s * dv + shift_u, params.centre_v + s * du + c * dv + shift_v};
  }
};

}  // namespace

std::array<double, 2> TwistingCurvesMaterial::point_at(int index, double w) const noexcept {
  return Motion(params_, w).apply(params_, params_.points[static_cast<std::size_t>(index)]);
}

void TwistingCurvesMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                          std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const double r2 = params_.radius * params_.radius;
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = kUnitParamBox.clamp(map_(uvw[s]));
    const Motion motion(params_, p.z);
    int material = params_.background;
    double best = r2;  // the nearest point strictly within the radius wins
    for (const TwistingCurvesParams::Point& point : params_.points) {
      const std::array<double, 2> q = motion.apply(params_, point);
      double du = p.x - q[0], dv = p.y - q[1];
      if (params_.wrap_u) du -= std::nearbyint(du);
      if (params_.wrap_v) dv -= std::nearbyint(dv);
      const double d2 = du * du + dv * dv;
      if (d2 < best) {
        best = d2;
        material = point.material;
      }
    }
    float* f = fractions.data() + s * m;
    std::fill(f, f + m, 0.0f);
    if (material != kVoidMaterial) f[material] = 1.0f;
  }
}

void TwistingCurvesMaterial::bounds(const ParamBox&, std::span<float> lo, std::span<float> hi) const {
  const auto m = static_cast<std::size_t>(num_materials());
  std::fill(lo.begin(), lo.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  std::fill(hi.begin(), hi.begin() + static_cast<std::ptrdiff_t>(m), 0.0f);
  for (const TwistingCurvesParams::Point& p : params_.points)
    if (p.material != kVoidMaterial) hi[static_cast<std::size_t>(p.material)] = 1.0f;
  if (params_.background != kVoidMaterial) hi[static_cast<std::size_t>(params_.background)] = 1.0f;
}

FractionEnclosure TwistingCurvesMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  FractionEnclosure e = MaterialFunction::enclose(box, xyz);
  e.sum_of_one_material();
  return e;
}

}  // namespace trivox
