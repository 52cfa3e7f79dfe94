#include "trivox/slice/slice_params.h"

#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

std::string_view to_string(TracingStrategy s) noexcept {
  switch (s) {
    case TracingStrategy::kNone: return "none";
    case TracingStrategy::kPreviousPoint: return "previous-point";
    case TracingStrategy::kPreviousLine: return "previous-line";
    case TracingStrategy::kFull: return "full";
    case TracingStrategy::kPredict: return "predict";
    case TracingStrategy::kFlood: return "flood";
  }
  return "unknown";
}

std::optional<TracingStrategy> parse_tracing_strategy(std::string_view name) noexcept {
  for (TracingStrategy s : {TracingStrategy::kNone, TracingStrategy::kPreviousPoint, TracingStrategy::kPreviousLine,
                            TracingStrategy::kFull, TracingStrategy::kPredict, TracingStrategy::kFlood})
    if (name == to_string(s)) return s;
  return std::nullopt;
}

void SliceParams::validate() const {
  if (!(newton.residual_tolerance_model > 0) || !std::isfinite(newton.residual_tolerance_model))
    throw Error(fmt::format("newton.residual_tolerance_model must be a positive number, got {}",
                            newton.residual_tolerance_model));
  if (newton.max_iterations < 1) throw Error("newton.max_iterations must be at least 1");
  if (global.max_boxes < 1) throw Error("global.max_boxes must be at least 1");
  if (outline_tolerance_mm && !(*outline_tolerance_mm > 0 && std::isfinite(*outline_tolerance_mm)))
    throw Error(fmt::format("outline_tolerance_mm must be a positive number, got {}", *outline_tolerance_mm));
  if (dither) dither->validate();
}

}  // namespace trivox
