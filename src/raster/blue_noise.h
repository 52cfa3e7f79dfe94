// A blue-noise threshold tile: a 64 x 64 arrangement of the ranks 0 .. 4095, each once, in
// which the pixels of every rank prefix (the darkest n) are spread as evenly as possible, with
// no low-frequency clumps. Thresholding a constant fraction f against it marks the first
// round(f * 4096) ranks: a pattern whose energy sits at high spatial frequencies, where the
// eye (and the printed part) averages it away. The tile wraps around toroidally, so tiling
// the plane with it shows no seams.
//
// The tile is made by Ulichney's void-and-cluster method ("The void-and-cluster method for
// dither array generation", Proc. SPIE 1913, 1993) with a Gaussian filter of sigma 1.5
// pixels, in integer arithmetic only (the filter table is built by fixed-point repeated
// multiplication, ties go to the first pixel in row-major order, the initial pattern comes
// from a fixed splitmix64 sequence), so the tile is the same on every machine and compiler.
// It is built once, on first use, and then shared read-only.
#pragma once

#include <array>
#include <cstdint>

namespace trivox {

inline constexpr int kBlueNoiseTileSize = 64;
inline constexpr int kBlueNoiseTileCells = kBlueNoiseTileSize * kBlueNoiseTileSize;

// Rank of cell (x, y) at index y * kBlueNoiseTileSize + x. Thread-safe.
const std::array<std::uint16_t, kBlueNoiseTileCells>& blue_noise_tile();

}  // namespace trivox
