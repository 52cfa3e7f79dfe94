// Internal to the dithering: the diffusion kernels as tap tables and the conversion of a
// fraction to fixed point. Shared by src/raster/dither.cpp and the reference implementation
// in tests/raster/dither_test.cpp, so that both read the same definitions.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

#include "trivox/raster/dither.h"

namespace trivox::detail {

// One receiver of a pixel's error: dx pixels ahead along the scan direction (negative =
// behind; mirrored on rows scanned right to left), dy rows below (>= 0; dy == 0 needs
// dx > 0 so that only unprocessed pixels receive), with an integer weight.
struct DiffusionTap {
  int dx;
  int dy;
  std::int32_t weight;
};

template <std::size_t N>
constexpr std::int32_t weight_sum(const std::array<DiffusionTap, N>& taps) noexcept {
  std::int32_t sum = 0;
  for (const DiffusionTap& t : taps) sum += t.weight;
  return sum;
}

template <std::size_t N>
constexpr int rows_spanned(const std::array<DiffusionTap, N>& taps) noexcept {
  int rows = 1;
  for (const DiffusionTap& t : taps) rows = std::max(rows, t.dy + 1);
  return rows;
}

// A kernel is a type with a constexpr tap table, so the dithering loop is instantiated per
// kernel with its weights and weight sum as compile-time constants. Adding Jarvis-Judice-
// Ninke or Stucki is one more such type, an enumerator and a case in each switch.
struct FloydSteinbergKernel {
  // Floyd and Steinberg, "An adaptive algorithm for spatial greyscale", Proc. SID 17 (1976).
  static constexpr std::array<DiffusionTap, 4> kTaps{{{1, 0, 7}, {-1, 1, 3}, {0, 1, 5}, {1, 1, 1}}};
  static constexpr std::int32_t kWeightSum = weight_sum(kTaps);
  static constexpr int kRows = rows_spanned(kTaps);
};

// The tap table of `kernel`; empty for a value outside the enumeration.
inline std::span<const DiffusionTap> diffusion_taps(DiffusionKernel kernel) noexcept {
  switch (kernel) {
    case DiffusionKernel::kFloydSteinberg:
      return FloydSteinbergKernel::kTaps;
  }
  return {};
}

// A fraction in fixed point: clamped to [0, 1], then rounded half up. f * 2^16 is exact in
// float, so the only rounding is the final one and the result does not depend on whether
// the compiler fuses the multiply and the add.
inline std::int32_t fraction_to_fixed(float f) noexcept {
  const float clamped = std::clamp(f, 0.0f, 1.0f);
  return static_cast<std::int32_t>(clamped * static_cast<float>(kDitherFixedOne) + 0.5f);
}

}  // namespace trivox::detail
