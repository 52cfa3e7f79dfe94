#include "trivox/raster/greyscale.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

GreyCalibration::GreyCalibration() : points_{{0.0, 255.0}} {}

GreyCalibration::GreyCalibration(std::vector<GreyPoint> points) : points_(std::move(points)) {
  if (points_.empty()) throw Error("a calibration curve needs at least one (value, grey) point");
  int direction = 0;  // +1 rising, -1 falling, 0 flat so far
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const GreyPoint& p = points_[i];
    if (!std::isfinite(p.value) || !std::isfinite(p.grey))
      throw Error(fmt::format("calibration point {}: ({}, {}) is not a pair of finite numbers", i, p.value, p.grey));
    if (p.grey < 0.0 || p.grey > 255.0)
      throw Error(fmt::format("calibration point {}: the grey {} is outside [0, 255]", i, p.grey));
    if (i == 0) continue;
    const GreyPoint& q = points_[i - 1];
    if (!(p.value > q.value))
      throw Error(
          fmt::format("calibration point {}: the values must increase, but {} follows {}", i, p.value, q.value));
    const int step = p.grey > q.grey ? 1 : p.grey < q.grey ? -1 : 0;
    if (step != 0 && direction != 0 && step != direction)
      throw Error(fmt::format("calibration point {}: the greys must be monotone, but {} follows {} after the curve {}",
                              i, p.grey, q.grey, direction > 0 ? "rose" : "fell"));
    if (step != 0) direction = step;
  }
}

double GreyCalibration::grey(double value) const noexcept {
  if (!(value > points_.front().value)) return points_.front().grey;  // NaN too
  if (value >= points_.back().value) return points_.back().grey;
  // The segment [points_[i - 1], points_[i]] holds value: value < points_[i].value.
  const auto it =
      std::upper_bound(points_.begin(), points_.end(), value, [](double v, const GreyPoint& p) { return v < p.value; });
  const GreyPoint& b = *it;
  const GreyPoint& a = *(it - 1);
  if (value == a.value) return a.grey;
  const double t = (value - a.value) / (b.value - a.value);
  return a.grey + t * (b.grey - a.grey);
}

std::uint8_t GreyCalibration::round_level(double grey) noexcept {
  const double clamped = std::clamp(grey, 0.0, 255.0);
  return static_cast<std::uint8_t>(std::floor(clamped + 0.5));
}

}  // namespace trivox
