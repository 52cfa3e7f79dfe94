// Dithering: turns per-pixel material fractions into one material (or void) per pixel, so
// that every neighbourhood of the label image holds each material in the proportion the
// fractions ask for. Two families (docs/DITHERING.md compares them):
//
// Vector error diffusion (DitherMethod::kErrorDiffusion), for m materials:
//  * a pixel's desired vector has m + 1 components in label order: component 0 is void
//    (1 - sum of fractions), component k is material k - 1; to it is added the error that
//    already-processed pixels diffused here;
//  * the pixel gets the label whose unit vector is nearest to the desired vector in Euclidean
//    distance, which is the largest component; ties go to the lowest label (void first);
//  * the error (desired - chosen unit vector) is split among the unprocessed neighbours by
//    the kernel's weights (Floyd-Steinberg, Jarvis-Judice-Ninke or Stucki), mirrored on rows
//    scanned right to left when the scan is serpentine.
//
// Pixels outside the inside mask stay void and take no part: they neither receive nor emit
// error, so error never bleeds into air or across a gap between two parts. A pixel's error
// is split among those of its kernel neighbours that are inside the mask and the image, the
// weights renormalised to their sum; material is thereby conserved along thin walls and at
// the image border, where plain error diffusion would drop the share. A pixel without such
// neighbours drops its error.
//
// Blue-noise thresholding (DitherMethod::kBlueNoise): each pixel compares one threshold t in
// [0, 1), read from a 64 x 64 blue-noise tile (src/raster/blue_noise.h) at its position, with the
// running sums of its components in label order, and takes the first component whose
// running sum exceeds t. Each pixel depends only on its own fractions and its position
// (x, y, layer), never on its neighbours or the scan, so the method is trivially parallel
// and tiling-independent; every 64 x 64 window holds every threshold exactly once.
//
// Both work in fixed point with kDitherFixedOne units per unit fraction (fractions are
// rounded to that grid on input), so the output is bit-identical across compilers, FMA
// contraction, SIMD width and machines; no random numbers are drawn at run time (the
// blue-noise tile is built by a deterministic integer algorithm). A diffusion share is
// error * weight / weight_sum truncated toward zero, and the last receiving neighbour in
// kernel order takes the remainder, so each component's error is conserved exactly.
//
// Layer variation: stacked layers with the same fractions would get the same pattern, which
// shows as vertical streaks on walls. With vary_by_layer the pattern depends on the layer
// index: error diffusion changes its scan orientation (rows top-down or bottom-up, first row
// left to right or right to left; a cycle of four) and breaks near-ties by a small bonus to
// one component, hashed from the layer and the pixel's position (for the choice only: the
// error diffused is unchanged, so a pure material never flips); blue noise shifts its tile by
// a per-layer offset (layer 0 unshifted). The orientations alone would mirror the layers of a
// part symmetric about its middle row into each other, repeating that row in pairs of
// layers; the tie-break leaves no row or column repeated (docs/DITHERING.md, "Streaks").
//
// Skin: with skin_voxels = k > 0, the pixels within k pixels (8-neighbour steps) of the
// outside of the mask or the image border take their nearest pure label (the largest
// component, ties to the lowest label: the material with the largest fraction, or void where
// void dominates) undithered, so the surface shows solid colour. The rest is dithered as if
// the skin were outside the mask (no error flows into or out of the skin). The skin is
// measured within the layer: top and bottom faces of a part are not skinned.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "trivox/raster/material_grid.h"

namespace trivox {

// Fixed-point units per unit fraction used by the dithering arithmetic.
inline constexpr std::int32_t kDitherFixedOne = std::int32_t{1} << 16;

enum class DitherMethod {
  kErrorDiffusion,  // vector error diffusion with DitherParams::kernel
  kBlueNoise,       // threshold against a blue-noise tile, per pixel position
};

enum class DiffusionKernel {
  // Floyd and Steinberg (1976): 7/16 to the next pixel in the scan direction; 3/16, 5/16,
  // 1/16 to the pixels behind, below and ahead on the next row.
  kFloydSteinberg,
  // Jarvis, Judice and Ninke (1976): 12 neighbours over three rows, weights /48.
  kJarvisJudiceNinke,
  // Stucki (1981): the Jarvis-Judice-Ninke footprint with weights /42.
  kStucki,
};
std::string_view to_string(DiffusionKernel kernel) noexcept;

struct DitherParams {
  DitherMethod method = DitherMethod::kErrorDiffusion;
  DiffusionKernel kernel = DiffusionKernel::kFloydSteinberg;  // for kErrorDiffusion
  // Error diffusion: scan even rows left to right and odd rows right to left (the kernel
  // mirrored), which breaks up the diagonal "worm" patterns of a raster scan.
  bool serpentine = true;
  // Change the scan orientation and the tie-break (error diffusion) or the tile offset (blue
  // noise) with the layer index, see above.
  bool vary_by_layer = true;
  // Width of the undithered skin in pixels; 0 = none. At most kMaxSkinVoxels.
  int skin_voxels = 0;
  // Input fractions may stray this far outside [0, 1], and their sum this far above 1, as
  // float rounding of the material functions; beyond it the input is an error. Each
  // fraction is clamped to [0, 1] before use; void takes what is left, slightly negative
  // when the sum is slightly above 1.
  float fraction_tolerance = 1e-4f;

  static constexpr int kMaxSkinVoxels = 1000;

  // Throws Error naming the field when the method or kernel is unknown, skin_voxels is
  // outside [0, kMaxSkinVoxels] or the tolerance is not a finite value in [0, 0.5).
  void validate() const;
};

// The named methods, as scene files and the CLI spell them: "floyd-steinberg",
// "jarvis-judice-ninke", "stucki" (error diffusion with that kernel) and "blue-noise".
std::span<const std::string_view> dither_method_names() noexcept;
// The name of params' method (and kernel, for error diffusion).
std::string_view dither_method_name(const DitherParams& params) noexcept;
// Sets params.method (and params.kernel) from a name; false, leaving params alone, for an
// unknown name.
bool set_dither_method(std::string_view name, DitherParams& params) noexcept;

// Dithers `fractions` inside `inside` into `labels`, which is resized (reallocated) only
// when its size differs from the grid's, so a caller slicing many layers reuses it. `layer`
// is the layer index (>= 0) the raster belongs to; it matters only with vary_by_layer.
// Throws Error when the params are invalid, the layer is negative, the mask's size differs
// from the grid's, or a fraction breaks MaterialGrid::check_fractions(fraction_tolerance).
// Error diffusion allocates only the kernel's rows of error buffer (1 + the rows it reaches
// below, of width_px * (m + 1) int32 each); a skin adds a depth plane and a mask per call.
// Thread-safe for distinct outputs: no shared mutable state.
void dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params, LabelImage& labels,
            int layer = 0);

// As above, returning a new label image.
LabelImage dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params = {},
                  int layer = 0);

namespace detail {
// dither() for a grid whose filler checked every pixel it wrote with
// MaterialGrid::check_pixel(params.fraction_tolerance) and left the others all 0: the same
// labels without a second pass over the grid (tens of megabytes a layer at printer
// resolution). The slicer fills its grids so.
void dither_checked_grid(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params,
                         LabelImage& labels, int layer);
}  // namespace detail

}  // namespace trivox
