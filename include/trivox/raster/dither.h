// Vector error diffusion: turns per-pixel material fractions into one material (or void)
// per pixel, so that every neighbourhood of the label image holds each material in the
// proportion the fractions ask for.
//
// The algorithm, for m materials:
//  * a pixel's desired vector has m + 1 components in label order: component 0 is void
//    (1 - sum of fractions), component k is material k - 1; to it is added the error that
//    already-processed pixels diffused here;
//  * the pixel gets the label whose unit vector is nearest to the desired vector in Euclidean
//    distance, which is the largest component; ties go to the lowest label (void first);
//  * the error (desired - chosen unit vector) is split among the unprocessed neighbours by
//    the kernel's weights (Floyd-Steinberg: 7/16 ahead, 3/16, 5/16, 1/16 on the next row),
//    mirrored on rows scanned right to left when the scan is serpentine.
//
// Pixels outside the inside mask stay void and take no part: they neither receive nor emit
// error, so error never bleeds into air or across a gap between two parts. A pixel's error
// is split among those of its kernel neighbours that are inside the mask and the image, the
// weights renormalised to their sum; material is thereby conserved along thin walls and at
// the image border, where plain Floyd-Steinberg would drop the share. A pixel without such
// neighbours drops its error.
//
// The arithmetic is fixed point with kDitherFixedOne units per unit fraction (fractions
// are rounded to that grid on input), so the output is bit-identical across compilers,
// FMA contraction, SIMD width and machines; no randomness is involved. A share is
// error * weight / weight_sum truncated toward zero, and the last receiving neighbour in
// kernel order takes the remainder, so each component's error is conserved exactly.
#pragma once

#include <cstdint>
#include <string_view>

#include "trivox/raster/material_grid.h"

namespace trivox {

// Fixed-point units per unit fraction used by the dithering arithmetic.
inline constexpr std::int32_t kDitherFixedOne = std::int32_t{1} << 16;

enum class DiffusionKernel {
  // Floyd and Steinberg (1976): 7/16 to the next pixel in the scan direction; 3/16, 5/16,
  // 1/16 to the pixels behind, below and ahead on the next row.
  kFloydSteinberg,
};
std::string_view to_string(DiffusionKernel kernel) noexcept;

struct DitherParams {
  DiffusionKernel kernel = DiffusionKernel::kFloydSteinberg;
  // Scan even rows left to right and odd rows right to left (the kernel mirrored), which
  // breaks up the diagonal "worm" patterns of a raster scan.
  bool serpentine = true;
  // Input fractions may stray this far outside [0, 1], and their sum this far above 1, as
  // float rounding of the material functions; beyond it the input is an error. Each
  // fraction is clamped to [0, 1] before use; void takes what is left, slightly negative
  // when the sum is slightly above 1.
  float fraction_tolerance = 1e-4f;

  // Throws Error naming the field when the kernel is unknown or the tolerance is not a
  // finite value in [0, 0.5).
  void validate() const;
};

// Dithers `fractions` inside `inside` into `labels`, which is resized (reallocated) only
// when its size differs from the grid's, so a caller slicing many layers reuses it.
// Throws Error when the params are invalid, the mask's size differs from the grid's, or a
// fraction breaks MaterialGrid::check_fractions(params.fraction_tolerance). Allocates only
// the kernel's rows of error buffer (2 rows of width_px * (m + 1) int32 for
// Floyd-Steinberg). Thread-safe for distinct outputs: no shared state.
void dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params,
            LabelImage& labels);

// As above, returning a new label image.
LabelImage dither(const MaterialGrid& fractions, const InsideMask& inside,
                  const DitherParams& params = {});

}  // namespace trivox
