#include "trivox/material/detail/scalar_gradient_material.h"

#include "material/enclosure_util.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "material/spline_coefficient_bounds.h"
#include "trivox/error.h"

namespace trivox {

namespace {

int stop_material_count(const std::vector<GradientStop>& stops) {
  if (stops.empty()) throw Error("a scalar gradient needs at least one stop");
  return static_cast<int>(stops.front().fractions.size());
}

void validate(const TensorSpline& field, const std::vector<GradientStop>& stops) {
  if (field.param_dim() != 3 || field.point_dim() != 1)
    throw Error(
        fmt::format("a scalar gradient needs a scalar trivariate field (3 parametric "
                    "directions, 1 component), got {} direction(s) and {} component(s)",
                    field.param_dim(), field.point_dim()));
  validate_gradient_stops(stops);
}

}  // namespace

void validate_gradient_stops(const std::vector<GradientStop>& stops) {
  if (stops.empty()) throw Error("a gradient needs at least one stop");
  for (std::size_t i = 0; i < stops.size(); ++i) {
    const GradientStop& stop = stops[i];
    if (!std::isfinite(stop.value)) throw Error(fmt::format("stop {}: value {} is not a finite number", i, stop.value));
    if (i > 0 && stop.value < stops[i - 1].value)
      throw Error(
          fmt::format("stop {}: value {} is below the previous stop's {}; stop values "
                      "must not decrease",
                      i, stop.value, stops[i - 1].value));
    if (stop.fractions.size() != stops.front().fractions.size())
      throw Error(fmt::format("stop {} has {} fractions, stop 0 has {}", i, stop.fractions.size(),
                              stops.front().fractions.size()));
    for (std::size_t j = 0; j < stop.fractions.size(); ++j)
      if (!std::isfinite(stop.fractions[j]))
        throw Error(fmt::format("stop {}: fraction {} is not a finite number", i, j));
  }
}

ScalarGradientMaterial::ScalarGradientMaterial(TensorSpline field, std::vector<GradientStop> stops,
                                               const ParamBox& cell_domain)
    : MaterialFunction(stop_material_count(stops)), field_(std::move(field)), stops_(std::move(stops)) {
  validate(field_, stops_);
  const ParamBox field_domain{{field_.lo(0), field_.lo(1), field_.lo(2)}, {field_.hi(0), field_.hi(1), field_.hi(2)}};
  map_ = AffineParamMap::between(cell_domain, field_domain);
}

void ScalarGradientMaterial::ramp(double s, std::span<float> out) const noexcept { gradient_ramp(stops_, s, out); }

void gradient_ramp(std::span<const GradientStop> stops, double s, std::span<float> out) noexcept {
  const std::size_t m = stops.front().fractions.size();
  if (std::isnan(s)) {  // passed on for the fraction policy to report
    std::fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(m), std::numeric_limits<float>::quiet_NaN());
    return;
  }
  // First stop whose value is above s: s lies in [stops[i-1], stops[i]). upper_bound makes the
  // later of two equal stops apply at their value (a step).
  const auto it =
      std::upper_bound(stops.begin(), stops.end(), s, [](double x, const GradientStop& g) { return x < g.value; });
  if (it == stops.begin() || it == stops.end()) {
    const GradientStop& end = it == stops.begin() ? stops.front() : stops.back();
    std::copy(end.fractions.begin(), end.fractions.end(), out.begin());
    return;
  }
  const GradientStop& a = *(it - 1);
  const GradientStop& b = *it;
  const double t = (s - a.value) / (b.value - a.value);  // b.value > a.value here
  for (std::size_t j = 0; j < m; ++j) out[j] = static_cast<float>((1.0 - t) * a.fractions[j] + t * b.fractions[j]);
}

void ScalarGradientMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3>,
                                          std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    const std::array<double, 3> t{p.x, p.y, p.z};
    double value = 0.0;
    field_.evaluate(t, std::span<double>(&value, 1));
    ramp(value, fractions.subspan(s * m, m));
  }
}

void ScalarGradientMaterial::bounds(const ParamBox& box, std::span<float> lo, std::span<float> hi) const {
  double slo = 0.0, shi = 0.0;
  detail::coefficient_bounds(field_, map_(box), std::span<double>(&slo, 1), std::span<double>(&shi, 1));
  // A piecewise-linear ramp takes its extremes over [slo, shi] at the ends or at stops inside.
  const auto m = static_cast<std::size_t>(num_materials());
  std::array<float, kMaxMaterials> at{};
  ramp(slo, at);
  std::copy(at.begin(), at.begin() + static_cast<std::ptrdiff_t>(m), lo.begin());
  std::copy(at.begin(), at.begin() + static_cast<std::ptrdiff_t>(m), hi.begin());
  auto include = [&](std::span<const float> f) {
    for (std::size_t j = 0; j < m; ++j) {
      lo[j] = std::min(lo[j], f[j]);
      hi[j] = std::max(hi[j], f[j]);
    }
  };
  ramp(shi, at);
  include(at);
  for (const GradientStop& stop : stops_)
    if (stop.value >= slo && stop.value <= shi) include(stop.fractions);
}

FractionEnclosure ScalarGradientMaterial::enclose(const ParamBox& box, const Box3&) const {
  const TensorSpline piece = detail::restricted_piece(field_, map_(box));
  const ParamBox whole{{piece.lo(0), piece.lo(1), piece.lo(2)}, {piece.hi(0), piece.hi(1), piece.hi(2)}};
  double slo = 0.0, shi = 0.0;
  detail::coefficient_bounds(piece, whole, std::span<double>(&slo, 1), std::span<double>(&shi, 1));
  return detail::ramp_enclosure(stops_, {slo - std::abs(slo) * 1e-12, shi + std::abs(shi) * 1e-12}, true);
}

}  // namespace trivox
