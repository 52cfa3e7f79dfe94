// Internal to the dithering: the diffusion kernels as tap tables, the conversion of a
// fraction to fixed point, and the per-layer scan orientation and tile offset. Shared by src/raster/dither.cpp and the
// reference implementation in tests/raster/dither_test.cpp, so that both read the same definitions.
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
// kernel with its weights and weight sum as compile-time constants. A new kernel is one more
// such type, an enumerator and a case in each switch.
struct FloydSteinbergKernel {
  // Floyd and Steinberg, "An adaptive algorithm for spatial greyscale", Proc. SID 17 (1976).
  static constexpr std::array<DiffusionTap, 4> kTaps{{{1, 0, 7}, {-1, 1, 3}, {0, 1, 5}, {1, 1, 1}}};
  static constexpr std::int32_t kWeightSum = weight_sum(kTaps);
  static constexpr int kRows = rows_spanned(kTaps);
};

struct JarvisJudiceNinkeKernel {
  // Jarvis, Judice and Ninke, "A survey of techniques for the display of continuous tone
  // pictures on bilevel displays", Computer Graphics and Image Processing 5 (1976).
  static constexpr std::array<DiffusionTap, 12> kTaps{{{1, 0, 7},
                                                       {2, 0, 5},
                                                       {-2, 1, 3},
                                                       {-1, 1, 5},
                                                       {0, 1, 7},
                                                       {1, 1, 5},
                                                       {2, 1, 3},
                                                       {-2, 2, 1},
                                                       {-1, 2, 3},
                                                       {0, 2, 5},
                                                       {1, 2, 3},
                                                       {2, 2, 1}}};
  static constexpr std::int32_t kWeightSum = weight_sum(kTaps);  // 48
  static constexpr int kRows = rows_spanned(kTaps);
};

struct StuckiKernel {
  // Stucki, "MECCA - a multiple-error correcting computation algorithm for bilevel image
  // hardcopy reproduction", IBM Research Report RZ1060 (1981).
  static constexpr std::array<DiffusionTap, 12> kTaps{{{1, 0, 8},
                                                       {2, 0, 4},
                                                       {-2, 1, 2},
                                                       {-1, 1, 4},
                                                       {0, 1, 8},
                                                       {1, 1, 4},
                                                       {2, 1, 2},
                                                       {-2, 2, 1},
                                                       {-1, 2, 2},
                                                       {0, 2, 4},
                                                       {1, 2, 2},
                                                       {2, 2, 1}}};
  static constexpr std::int32_t kWeightSum = weight_sum(kTaps);  // 42
  static constexpr int kRows = rows_spanned(kTaps);
};

// The tap table of `kernel`; empty for a value outside the enumeration.
inline std::span<const DiffusionTap> diffusion_taps(DiffusionKernel kernel) noexcept {
  switch (kernel) {
    case DiffusionKernel::kFloydSteinberg: return FloydSteinbergKernel::kTaps;
    case DiffusionKernel::kJarvisJudiceNinke: return JarvisJudiceNinkeKernel::kTaps;
    case DiffusionKernel::kStucki: return StuckiKernel::kTaps;
  }
  return {};
}

// How error diffusion walks a layer: logical row r is image row r (top-down) or
// height - 1 - r (bottom-up); the first logical row runs left to right unless
// first_row_reversed. With variation the four orientations cycle so that neighbouring layers
// differ in both: layer 0 top-down left-first, 1 bottom-up right-first, 2 top-down
// right-first, 3 bottom-up left-first.
struct ScanOrientation {
  bool bottom_up = false;
  bool first_row_reversed = false;
};
inline ScanOrientation scan_orientation(int layer, bool vary_by_layer) noexcept {
  if (!vary_by_layer) return {};
  const unsigned l = static_cast<unsigned>(layer);
  return {(l & 1u) != 0, ((l + l / 2) & 1u) != 0};
}

// Layer variation's tie-break: with variation, error diffusion adds at every pixel a small
// bonus to one component, both chosen by a hash of (layer, image row, column), before it picks
// the largest component; the error it diffuses is that of the unperturbed desire, so the
// material is conserved exactly as without it. Only choices within the bonus of a tie can
// change, so a pure material never flips (its margin is a whole unit) and a mix is as exact
// as before. But a choice that changes changes the pattern after it, so layers whose scans
// are mirror images of each other (a part symmetric about its middle row or column) or the
// same (layers four apart) no longer repeat a row or a column: the scan orientations alone
// leave the middle row of a symmetric part identical in pairs of layers, a streak plane.
// The first rows after the part starts in a column (in scan order) are regular (their errors
// take few values, none near a tie), so there the bonus is larger. The hash depends on the
// layer and the image position only, never on the scan or the schedule.
inline constexpr std::int32_t kTieBreakBonusMax = kDitherFixedOne / 128;
inline constexpr std::int32_t kStartBonusMax = kDitherFixedOne / 4;
inline constexpr int kStartRows = 16;  // rows of a column from where the part starts in the scan

// A 32-bit integer hash with good avalanche (two multiply-xorshift rounds).
inline std::uint32_t mix32(std::uint32_t h) noexcept {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}
inline std::uint32_t tie_break_row_seed(int layer, int image_row) noexcept {
  return mix32(mix32(static_cast<std::uint32_t>(layer) * 0x9e3779b9u + 0x632be5abu) ^
               (static_cast<std::uint32_t>(image_row) * 0x85ebca6bu));
}
struct TieBreak {
  std::uint32_t component;  // in [0, components)
  std::int32_t bonus;       // in [0, the bonus's maximum)
};
// `depth`: the pixel's rows since the part started in its column, in scan order (0 on the
// row where it starts). One multiply-xorshift round of the row's seed and the column is
// enough to decorrelate neighbouring pixels; the row seed is fully mixed.
inline TieBreak tie_break(std::uint32_t row_seed, int col, std::uint32_t components, int depth) noexcept {
  static_assert(kStartBonusMax == kDitherFixedOne >> 2 && kTieBreakBonusMax == kDitherFixedOne >> 7,
                "the bonus is the hash's low 16 bits shifted");
  std::uint32_t n = row_seed + static_cast<std::uint32_t>(col) * 0x9e3779b9u;
  n ^= n >> 16;
  n *= 0x7feb352du;
  n ^= n >> 15;
  return {((n >> 16) * components) >> 16, static_cast<std::int32_t>((n & 0xffffu) >> (depth < kStartRows ? 2 : 9))};
}

// The blue-noise tile's offset for a layer: pixel (x, y) reads tile cell
// ((x + dx) mod 64, (y + dy) mod 64). Odd multipliers walk all 64 offsets along each axis
// before repeating, and consecutive layers land far apart.
struct TileOffset {
  int dx = 0;
  int dy = 0;
};
inline TileOffset tile_offset(int layer, bool vary_by_layer) noexcept {
  if (!vary_by_layer) return {};
  const unsigned l = static_cast<unsigned>(layer);
  return {static_cast<int>((l * 29u) % 64u), static_cast<int>((l * 45u) % 64u)};
}

// The threshold of a tile rank in fixed point: the centre of its 1/4096 slot of [0, 1).
inline std::int32_t rank_threshold(std::uint16_t rank) noexcept {
  static_assert(kDitherFixedOne % 4096 == 0);
  constexpr std::int32_t kSlot = kDitherFixedOne / 4096;
  return static_cast<std::int32_t>(rank) * kSlot + kSlot / 2;
}

// A fraction in fixed point: clamped to [0, 1], then rounded half up. f * 2^16 is exact in
// float, so the only rounding is the final one and the result does not depend on whether
// the compiler fuses the multiply and the add.
inline std::int32_t fraction_to_fixed(float f) noexcept {
  const float clamped = std::clamp(f, 0.0f, 1.0f);
  return static_cast<std::int32_t>(clamped * static_cast<float>(kDitherFixedOne) + 0.5f);
}

}  // namespace trivox::detail
