// Greyscale layers for masked-resin (LCD/DLP) printers: the grey level of a pixel sets its
// exposure, and through it the stiffness of the cured resin there (greyscale printing of
// graded materials; docs/SCENE.md, "Greyscale").
//
// A calibration curve maps a scalar (a material's fraction, or any scalar source of the
// scene) to a grey level: measured pairs (value, grey) of one printer and resin, joined by
// straight lines and held constant beyond the first and the last. The greys must be monotone
// in the value (exposure grows, or shrinks, with it), so every grey of the range stands for one
// value interval.
#pragma once

#include <cstdint>
#include <vector>

#include "trivox/raster/material_grid.h"

namespace trivox {

// An 8-bit grey layer, row-major like the label images: 0 = no exposure (outside the part or
// void), 255 = full exposure.
class GreyImage : public PixelPlane<std::uint8_t> {
 public:
  using PixelPlane::PixelPlane;
};

struct GreyPoint {
  double value = 0;
  double grey = 0;  // 0 to 255

  bool operator==(const GreyPoint&) const = default;
};

class GreyCalibration {
 public:
  // Every grey exposes fully: value v maps to 255 everywhere.
  GreyCalibration();
  // Throws Error naming the rule when `points` is empty, a value or grey is not finite, a
  // grey is outside [0, 255], the values do not strictly increase, or the greys are not
  // monotone (non-decreasing or non-increasing).
  explicit GreyCalibration(std::vector<GreyPoint> points);

  const std::vector<GreyPoint>& points() const noexcept { return points_; }

  // The curve at `value`: linear between neighbouring points, the end greys beyond them. At
  // a point's value it is that point's grey exactly. A NaN value gives the first grey.
  double grey(double value) const noexcept;
  // grey(value) rounded to the nearest level (halves up).
  std::uint8_t level(double value) const noexcept { return round_level(grey(value)); }
  // A grey in [0, 255] rounded to the nearest level (halves up).
  static std::uint8_t round_level(double grey) noexcept;

  bool operator==(const GreyCalibration&) const = default;

 private:
  std::vector<GreyPoint> points_;
};

}  // namespace trivox
