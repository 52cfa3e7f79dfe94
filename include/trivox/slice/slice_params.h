// Settings of the slicer (Algorithm 1 of the paper), with units in the names.
#pragma once

#include <optional>
#include <string_view>

#include "trivox/inverse/invert.h"
#include "trivox/raster/dither.h"

namespace trivox {

// How a pixel's inverse is seeded (the paper's Table 1). Each strategy falls back to the
// global solver when Newton from its seeds does not converge.
enum class TracingStrategy {
  kNone,           // global solve for every pixel
  kPreviousPoint,  // the previous pixel of the row
  kPreviousLine,   // the previous pixel of the row, else the pixel above
  kFull,           // any already solved 8-neighbour (left, up-left, up, up-right)
};
std::string_view to_string(TracingStrategy s) noexcept;
// Parses "none", "previous-point", "previous-line", "full"; nullopt otherwise.
std::optional<TracingStrategy> parse_tracing_strategy(std::string_view name) noexcept;

struct SliceParams {
  TracingStrategy tracing = TracingStrategy::kFull;
  InverseParams newton;  // residual tolerance in mm for every inside pixel
  GlobalSolveParams global;
  // Largest distance (mm) between a cell's boundary and its triangulated outline. Pixels
  // whose centres lie within this distance of the outline are decided by the exact inverse;
  // the rest by the outline. A quarter of the finest pixel pitch by default.
  std::optional<double> outline_tolerance_mm;
  // The dithering; absent: the scene's "dithering" settings, else DitherParams' defaults.
  std::optional<DitherParams> dither;

  // Throws trivox::Error naming the field.
  void validate() const;
};

}  // namespace trivox
