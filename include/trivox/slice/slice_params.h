// Settings of the slicer (Algorithm 1 of the paper), with units in the names.
#pragma once

#include <atomic>
#include <cstdint>

#include <optional>
#include <string_view>

#include "trivox/inverse/invert.h"
#include "trivox/raster/dither.h"

namespace trivox {

// How a pixel's inverse is seeded. The first four are the paper's Table 1; the last two add
// predictors of trivox's own. Each strategy falls back to the global solver when Newton from
// its seeds does not converge.
enum class TracingStrategy {
  kNone,           // global solve for every pixel
  kPreviousPoint,  // the previous pixel of the row
  kPreviousLine,   // the previous pixel of the row, else the pixel above
  kFull,           // any already solved 8-neighbour (left, up-left, up, up-right)
  kPredict,        // full, but first the cubic through the row's last four solutions,
                   // checked with one evaluation (SLICING.md)
  kFlood,          // predict, then the nearest solved pixel of this row or the row above
                   // (within 64 pixels) before the global solver: a span that starts where
                   // the row above had no solved neighbour is reached from inside the cell
};
std::string_view to_string(TracingStrategy s) noexcept;
// Parses "none", "previous-point", "previous-line", "full", "predict", "flood"; nullopt
// otherwise.
std::optional<TracingStrategy> parse_tracing_strategy(std::string_view name) noexcept;

struct SliceParams {
  TracingStrategy tracing = TracingStrategy::kFlood;
  // Every inside pixel's (u, v, w) satisfies |V(u,v,w) - pixel centre| <= this residual
  // tolerance. The slicer's default is 1e-6 mm, a nanometre: 40000 times below the 600 dpi
  // pitch, so it moves a voxel's material only when the voxel centre lies within about a
  // nanometre of a material boundary or a face, while it lets the row predictor settle most
  // pixels with one evaluation. (invert() and `trivox probe` default to 1e-8.)
  InverseParams newton{.residual_tolerance_model = 1e-6};
  GlobalSolveParams global;
  // Largest distance (mm) between a cell's boundary and its triangulated outline. Pixels
  // whose centres lie within this distance of the outline are decided by the exact inverse;
  // the rest by the outline. An eighth of the finest pitch (pixel or layer) by default: the
  // narrower the band, the fewer global solves prove its pixels outside. Model-space trim
  // shells are tessellated to half this tolerance when it is given, else to an eighth of
  // the finest pitch.
  std::optional<double> outline_tolerance_mm;
  // Cells trimmed "inside" a parametric trim invert only the pixels within the trim's
  // outline (its tessellation mapped through the cell's volume, cut by the layer, widened by
  // twice the outline tolerance). Off, every pixel within the cell's own outline is inverted
  // and then tested: the same output, more inversions (the reference the narrowing is
  // checked against).
  bool parametric_outlines = true;
  // Cells with "volume" or "shell" trim clauses (whose own volume is not traced for the whole
  // layer) invert only the pixels that pass those clauses, decided from the trimming volume's
  // inverse and the shell's cut by the layer. Off, every pixel within the cell's own outline
  // is inverted and then tested: the same output, more inversions (the reference the
  // narrowing is checked against).
  bool model_space_narrowing = true;
  // The frame (bitmap and layers) from each cell's volume cut down to the boxes of the
  // model-space "inside" trims it lies inside (Slicer::object_bounds). Off, from the volumes
  // alone: a larger frame around the same voxels (the reference the tight frame is checked
  // against, and the frame of releases before it).
  bool frame_from_trims = true;
  // With trivox's own strategies (predict, flood), cells of one constant material,
  // untrimmed, without a greyscale source and not folded take the pixels their outline
  // decides inside (centres inside its cut and farther than the band from it) without
  // inverting them: no (u, v, w) is needed to give them their material, so only the band
  // (and 8 pixels beside it, to seed it) is traced. Off, every candidate pixel is inverted:
  // the same inside pixels except where a pixel centre lies within the residual tolerance
  // of a face, which either answer meets (the reference the fill is checked against).
  bool fill_constant_interiors = true;
  // The dithering; absent: the scene's "dithering" settings, else DitherParams' defaults.
  std::optional<DitherParams> dither;
  // Memory (bytes) the job may use, 0 for no limit. The cells' outline meshes get at most
  // half of it, shared out before any is built (each also stays within a budget set by its
  // size in pixels; SLICING.md, "outline meshes"); a mesh its budget cuts short is coarser
  // and the band of pixels decided by the exact inverse wider, so the output is the same.
  std::uint64_t memory_limit_bytes = 0;
  // Checked by the slicer's set-up (outline and shell meshes) and between rows of a layer:
  // once it is true, the constructor and slice_layer throw CancelledError. May be set from a
  // signal handler. Not a setting of the output (nothing in the manifest).
  const std::atomic<bool>* stop = nullptr;

  // Throws trivox::Error naming the field.
  void validate() const;
};

}  // namespace trivox
