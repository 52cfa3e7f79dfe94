#include "trivox/raster/dither.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "raster/blue_noise.h"
#include "raster/dither_kernels.h"
#include "raster/skin.h"

namespace trivox {

std::string_view to_string(DiffusionKernel kernel) noexcept {
  switch (kernel) {
    case DiffusionKernel::kFloydSteinberg: return "floyd-steinberg";
    case DiffusionKernel::kJarvisJudiceNinke: return "jarvis-judice-ninke";
    case DiffusionKernel::kStucki: return "stucki";
  }
  return "unknown";
}

namespace {
constexpr std::string_view kBlueNoiseName = "blue-noise";
constexpr std::string_view kMethodNames[] = {"floyd-steinberg", "jarvis-judice-ninke", "stucki", kBlueNoiseName};
}  // namespace

std::span<const std::string_view> dither_method_names() noexcept { return kMethodNames; }

std::string_view dither_method_name(const DitherParams& params) noexcept {
  return params.method == DitherMethod::kBlueNoise ? kBlueNoiseName : to_string(params.kernel);
}

bool set_dither_method(std::string_view name, DitherParams& params) noexcept {
  if (name == kBlueNoiseName) {
    params.method = DitherMethod::kBlueNoise;
    return true;
  }
  for (DiffusionKernel k :
       {DiffusionKernel::kFloydSteinberg, DiffusionKernel::kJarvisJudiceNinke, DiffusionKernel::kStucki}) {
    if (name == to_string(k)) {
      params.method = DitherMethod::kErrorDiffusion;
      params.kernel = k;
      return true;
    }
  }
  return false;
}

void DitherParams::validate() const {
  if (method != DitherMethod::kErrorDiffusion && method != DitherMethod::kBlueNoise) {
    throw Error(fmt::format("dither params: method = {} is not a known dithering method", static_cast<int>(method)));
  }
  if (detail::diffusion_taps(kernel).empty()) {
    throw Error(fmt::format("dither params: kernel = {} is not a known diffusion kernel", static_cast<int>(kernel)));
  }
  if (skin_voxels < 0 || skin_voxels > kMaxSkinVoxels) {
    throw Error(fmt::format("dither params: skin_voxels = {} is not in [0, {}]", skin_voxels, kMaxSkinVoxels));
  }
  if (!std::isfinite(fraction_tolerance) || fraction_tolerance < 0.0f || fraction_tolerance >= 0.5f) {
    throw Error(fmt::format("dither params: fraction_tolerance = {} is not in [0, 0.5)", fraction_tolerance));
  }
}

namespace {

// Splits error vector `e` (num_components values) among `count` receivers with weights
// summing to `weight_sum`: error * weight / weight_sum truncated toward zero, the last
// receiver taking the remainder so that each component is conserved exactly. The product is
// formed in 64 bits; the accumulated error itself stays within a few units (2^16 each) in
// practice (the tests measure it), far from the int32 limit of 32768 units.
inline void spread(const std::int32_t* e, std::size_t num_components, std::int32_t* const* to,
                   const std::int32_t* weights, int count, std::int32_t weight_sum) noexcept {
  for (std::size_t c = 0; c < num_components; ++c) {
    const std::int64_t error = e[c];
    std::int32_t given = 0;
    for (int t = 0; t + 1 < count; ++t) {
      const auto share = static_cast<std::int32_t>(error * weights[t] / weight_sum);
      to[t][c] += share;
      given += share;
    }
    to[count - 1][c] += e[c] - given;
  }
}

// The same split when every tap receives: weights and their sum are compile-time constants,
// so the divisions become multiplies and shifts, and each receiver is swept once over
// contiguous components. Identical results to spread().
template <class Kernel>
inline void spread_all(const std::int32_t* e, std::size_t num_components, std::int32_t* const* to) noexcept {
  constexpr auto& taps = Kernel::kTaps;
  constexpr std::size_t kLast = taps.size() - 1;
  std::int32_t* const last = to[kLast];
  for (std::size_t c = 0; c < num_components; ++c) last[c] += e[c];
  for (std::size_t t = 0; t < kLast; ++t) {
    std::int32_t* const receiver = to[t];
    const std::int64_t weight = taps[t].weight;
    for (std::size_t c = 0; c < num_components; ++c) {
      const auto share = static_cast<std::int32_t>(e[c] * weight / Kernel::kWeightSum);
      receiver[c] += share;
      last[c] -= share;
    }
  }
}

// The first and last inside pixel of a mask row (first > last when there is none), found
// eight mask bytes at a time across the empty ends.
struct InsideSpan {
  int first, last;
};
InsideSpan inside_span(const std::uint8_t* mask, int width) noexcept {
  auto empty8 = [mask](int x) {
    std::uint64_t word;
    std::memcpy(&word, mask + x, sizeof word);
    return word == 0;
  };
  int first = 0;
  while (first + 8 <= width && empty8(first)) first += 8;
  while (first < width && mask[first] == 0) ++first;
  if (first == width) return {width, width - 1};
  int last = width - 1;
  while (last - 7 > first && empty8(last - 7)) last -= 8;
  while (mask[last] == 0) --last;
  return {first, last};
}

// Diffuses the error e of the pixel at x (its row's direction `dir`) to the taps of Kernel
// that are inside: error_rows[r] and mask_rows[r] are the error and mask rows r below
// (mask_rows[r] null past the last row).
template <class Kernel>
[[gnu::always_inline]] inline void diffuse(const std::int32_t* e, std::size_t num_components, int x, int dir, int width,
                                           std::int32_t* const* error_rows, const std::uint8_t* const* mask_rows) {
  constexpr auto& taps = Kernel::kTaps;
  constexpr int kNumTaps = static_cast<int>(taps.size());
  // Inside the part, every tap receives: the receivers then follow from x alone, so the
  // common case is decided first and its pointers stay in registers.
  bool all_receive = true;
  for (const detail::DiffusionTap& tap : taps) {
    const int nx = x + dir * tap.dx;
    const std::uint8_t* mask_row = mask_rows[tap.dy];
    all_receive = all_receive && nx >= 0 && nx < width && mask_row != nullptr && mask_row[nx] != 0;
  }
  if (all_receive) {
    std::int32_t* to[kNumTaps];
    for (int t = 0; t < kNumTaps; ++t)
      to[t] = error_rows[taps[static_cast<std::size_t>(t)].dy] +
              static_cast<std::size_t>(x + dir * taps[static_cast<std::size_t>(t)].dx) * num_components;
    spread_all<Kernel>(e, num_components, to);
    return;
  }
  std::int32_t* to[kNumTaps];
  std::int32_t weights[kNumTaps];
  int count = 0;
  std::int32_t weight_sum = 0;
  for (const detail::DiffusionTap& tap : taps) {
    const int nx = x + dir * tap.dx;
    const std::uint8_t* mask_row = mask_rows[tap.dy];
    if (nx < 0 || nx >= width || mask_row == nullptr || mask_row[nx] == 0) continue;
    to[count] = error_rows[tap.dy] + static_cast<std::size_t>(nx) * num_components;
    weights[count] = tap.weight;
    weight_sum += tap.weight;
    ++count;
  }
  if (count > 0) spread(e, num_components, to, weights, count, weight_sum);
}

// Error rows live in a ring of Kernel::kRows rows, each width_px * (m + 1) int32: row y + r
// is slot (y + r) % kRows. After row y is done its slot is cleared and becomes row
// y + kRows.
// Logical row y is image row image_row(y) (see detail::ScanOrientation).
// kComponents is m + 1 when it is known at compile time (scenes with one to eight
// materials: the per-component loops then unroll), or 0 for any other count.
// With `tie_break`, the choice at each pixel takes layer `layer`'s tie-break bonus
// (detail::tie_break).
template <class Kernel, std::size_t kComponents>
void dither_with(const MaterialGrid& fractions, const InsideMask& inside, bool serpentine,
                 detail::ScanOrientation orientation, bool tie_break, int layer, LabelImage& labels) {
  constexpr int kRows = Kernel::kRows;

  const int width = fractions.width_px();
  const int height = fractions.height_px();
  const std::size_t m = kComponents > 0 ? kComponents - 1 : static_cast<std::size_t>(fractions.num_materials());
  const std::size_t num_components = m + 1;
  const std::size_t row_values = static_cast<std::size_t>(width) * num_components;
  std::vector<std::int32_t> error(static_cast<std::size_t>(kRows) * row_values, 0);

  // With the tie-break: per column, the rows since the part started there (read only where
  // the row before is inside, so only inside pixels need to write it).
  std::vector<std::uint8_t> run(tie_break ? static_cast<std::size_t>(width) : 0, 0);
  auto image_row = [&](int y) { return orientation.bottom_up ? height - 1 - y : y; };
  for (int y = 0; y < height; ++y) {
    const bool reverse = (serpentine && (y % 2 == 1)) != orientation.first_row_reversed;
    const int dir = reverse ? -1 : 1;
    std::int32_t* error_rows[kRows];
    const std::uint8_t* mask_rows[kRows];
    for (int r = 0; r < kRows; ++r) {
      error_rows[r] = error.data() + static_cast<std::size_t>((y + r) % kRows) * row_values;
      mask_rows[r] = y + r < height ? inside.row(image_row(y + r)).data() : nullptr;
    }
    const float* fraction_row = fractions.row(image_row(y)).data();
    std::uint8_t* label_row = labels.row(image_row(y)).data();
    const std::uint32_t row_seed = tie_break ? detail::tie_break_row_seed(layer, image_row(y)) : 0;
    const std::uint8_t* above = y > 0 ? inside.row(image_row(y - 1)).data() : nullptr;

    // Only the columns from the row's first inside pixel to its last can hold a label or
    // receive error (every receiver is an inside pixel), so the rest of the row is void.
    std::fill(label_row, label_row + width, LabelImage::kVoid);
    const InsideSpan span = inside_span(mask_rows[0], width);
    if (span.first > span.last) continue;  // its error row was never written
    for (int i = 0; i <= span.last - span.first; ++i) {
      const int x = reverse ? span.last - i : span.first + i;
      if (mask_rows[0][x] == 0) continue;  // void, as filled above
      // The desired vector: the error received so far plus the pixel's fractions. With the
      // component count known at compile time it lives in registers (`local`); otherwise in
      // place, in the pixel's slot of the error row (which nothing reads after this pixel).
      std::int32_t* const slot = error_rows[0] + static_cast<std::size_t>(x) * num_components;
      std::int32_t local[kComponents > 0 ? kComponents : 1];
      std::int32_t* const e = kComponents > 0 ? local : slot;
      const float* f = fraction_row + static_cast<std::size_t>(x) * m;
      std::int32_t material_total = 0;
      for (std::size_t k = 0; k < m; ++k) {
        const std::int32_t q = detail::fraction_to_fixed(f[k]);
        e[k + 1] = slot[k + 1] + q;
        material_total += q;
      }
      e[0] = slot[0] + (kDitherFixedOne - material_total);

      // With layer variation one component gets its tie-break bonus, for the choice only.
      detail::TieBreak tb{0, 0};
      if (tie_break) {
        const int depth = above != nullptr && above[x] != 0 ? std::min(run[static_cast<std::size_t>(x)] + 1, 255) : 0;
        run[static_cast<std::size_t>(x)] = static_cast<std::uint8_t>(depth);
        tb = detail::tie_break(row_seed, x, static_cast<std::uint32_t>(num_components), depth);
      }
      // The largest component wins, ties to the lowest label. Branch-free on purpose (masks,
      // not conditionals the compiler may turn back into jumps): which component wins is
      // data-dependent noise, the worst case for a branch predictor. The bonus is added by a
      // mask too, so that e stays in registers.
      const auto bonus_of = [&](std::size_t c) {
        return tb.bonus & -static_cast<std::int32_t>(static_cast<std::uint32_t>(c) == tb.component);
      };
      std::int32_t best = 0;
      std::int32_t best_value = e[0] + bonus_of(0);
      for (std::size_t c = 1; c < num_components; ++c) {
        const std::int32_t value = e[c] + bonus_of(c);
        const std::int32_t larger = -static_cast<std::int32_t>(value > best_value);
        best = (best & ~larger) | (static_cast<std::int32_t>(c) & larger);
        best_value = std::max(best_value, value);
      }
      label_row[x] = static_cast<std::uint8_t>(best);
      // Now the error to diffuse.
      for (std::size_t c = 0; c < num_components; ++c)
        e[c] -= kDitherFixedOne & -static_cast<std::int32_t>(static_cast<std::int32_t>(c) == best);

      // A pixel whose choice matches its desire exactly (a pure material with no error
      // received, the common case inside a part of pure materials) has nothing to diffuse:
      // every receiver would add zero.
      std::int32_t any_error = 0;
      for (std::size_t c = 0; c < num_components; ++c) any_error |= e[c];
      if (any_error == 0) continue;

      diffuse<Kernel>(e, num_components, x, dir, width, error_rows, mask_rows);
    }
    std::fill(error_rows[0] + static_cast<std::size_t>(span.first) * num_components,
              error_rows[0] + static_cast<std::size_t>(span.last + 1) * num_components, 0);
  }
}

// The label of the first component (void, then the materials) whose running sum exceeds
// the pixel's threshold. Void is what the materials leave, clamped at 0, so the running sum
// ends at >= kDitherFixedOne > any threshold.
inline std::uint8_t threshold_label(const float* f, std::size_t m, std::int32_t threshold) noexcept {
  std::int32_t material_total = 0;
  for (std::size_t k = 0; k < m; ++k) material_total += detail::fraction_to_fixed(f[k]);
  std::int32_t running = std::max(0, kDitherFixedOne - material_total);
  if (threshold < running) return LabelImage::kVoid;
  for (std::size_t k = 0; k + 1 < m; ++k) {
    running += detail::fraction_to_fixed(f[k]);
    if (threshold < running) return LabelImage::label_of_material(static_cast<int>(k));
  }
  return LabelImage::label_of_material(static_cast<int>(m - 1));
}

void blue_noise_threshold(const MaterialGrid& fractions, const InsideMask& inside, detail::TileOffset offset,
                          LabelImage& labels) {
  const auto& tile = blue_noise_tile();
  const std::size_t m = static_cast<std::size_t>(fractions.num_materials());
  constexpr int kMask = kBlueNoiseTileSize - 1;
  static_assert((kBlueNoiseTileSize & kMask) == 0, "the tile size is a power of two");
  for (int y = 0; y < fractions.height_px(); ++y) {
    const float* fraction_row = fractions.row(y).data();
    const std::uint8_t* mask_row = inside.row(y).data();
    std::uint8_t* label_row = labels.row(y).data();
    const std::uint16_t* tile_row =
        tile.data() + static_cast<std::size_t>(((y + offset.dy) & kMask) * kBlueNoiseTileSize);
    for (int x = 0; x < fractions.width_px(); ++x) {
      if (mask_row[x] == 0) {
        label_row[x] = LabelImage::kVoid;
        continue;
      }
      const std::int32_t threshold = detail::rank_threshold(tile_row[(x + offset.dx) & kMask]);
      label_row[x] = threshold_label(fraction_row + static_cast<std::size_t>(x) * m, m, threshold);
    }
  }
}

// The nearest pure label of a pixel: the largest of its m + 1 components (void first), ties
// to the lowest label.
std::uint8_t nearest_pure_label(std::span<const float> f) noexcept {
  std::int32_t material_total = 0;
  for (float v : f) material_total += detail::fraction_to_fixed(v);
  std::uint8_t best = LabelImage::kVoid;
  std::int32_t best_value = kDitherFixedOne - material_total;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const std::int32_t q = detail::fraction_to_fixed(f[k]);
    if (q > best_value) {
      best = LabelImage::label_of_material(static_cast<int>(k));
      best_value = q;
    }
  }
  return best;
}

// dither_with for the scene's material count: one instantiation per count from 1 to 8
// materials (a J850 takes 7, plus support), the general loop beyond.
template <class Kernel>
void dither_with_components(const MaterialGrid& fractions, const InsideMask& inside, bool serpentine,
                            detail::ScanOrientation orientation, bool tie_break, int layer, LabelImage& labels) {
  const auto run = [&](auto components) {
    dither_with<Kernel, decltype(components)::value>(fractions, inside, serpentine, orientation, tie_break, layer,
                                                     labels);
  };
  switch (fractions.num_materials()) {
    case 1: return run(std::integral_constant<std::size_t, 2>{});
    case 2: return run(std::integral_constant<std::size_t, 3>{});
    case 3: return run(std::integral_constant<std::size_t, 4>{});
    case 4: return run(std::integral_constant<std::size_t, 5>{});
    case 5: return run(std::integral_constant<std::size_t, 6>{});
    case 6: return run(std::integral_constant<std::size_t, 7>{});
    case 7: return run(std::integral_constant<std::size_t, 8>{});
    case 8: return run(std::integral_constant<std::size_t, 9>{});
    default: return run(std::integral_constant<std::size_t, 0>{});
  }
}

void dither_core(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params, int layer,
                 LabelImage& labels) {
  if (params.method == DitherMethod::kBlueNoise) {
    blue_noise_threshold(fractions, inside, detail::tile_offset(layer, params.vary_by_layer), labels);
    return;
  }
  const detail::ScanOrientation orientation = detail::scan_orientation(layer, params.vary_by_layer);
  const bool tie_break = params.vary_by_layer;
  switch (params.kernel) {
    case DiffusionKernel::kFloydSteinberg:
      dither_with_components<detail::FloydSteinbergKernel>(fractions, inside, params.serpentine, orientation, tie_break,
                                                           layer, labels);
      return;
    case DiffusionKernel::kJarvisJudiceNinke:
      dither_with_components<detail::JarvisJudiceNinkeKernel>(fractions, inside, params.serpentine, orientation,
                                                              tie_break, layer, labels);
      return;
    case DiffusionKernel::kStucki:
      dither_with_components<detail::StuckiKernel>(fractions, inside, params.serpentine, orientation, tie_break, layer,
                                                   labels);
      return;
  }
}

}  // namespace

namespace {

void dither_grid(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params,
                 LabelImage& labels, int layer, bool check_grid) {
  params.validate();
  if (layer < 0) throw Error(fmt::format("dither: layer = {} is negative", layer));
  if (inside.width_px() != fractions.width_px() || inside.height_px() != fractions.height_px()) {
    throw Error(fmt::format("dither: inside mask is {} x {} px but the material grid is {} x {}", inside.width_px(),
                            inside.height_px(), fractions.width_px(), fractions.height_px()));
  }
  if (check_grid) fractions.check_fractions(params.fraction_tolerance);
  if (labels.width_px() != fractions.width_px() || labels.height_px() != fractions.height_px()) {
    labels = LabelImage(fractions.width_px(), fractions.height_px());
  }
  if (params.skin_voxels == 0) {
    dither_core(fractions, inside, params, layer, labels);
    return;
  }
  // The skin takes its nearest pure labels; the core is dithered as if the skin were outside.
  const auto cap = static_cast<std::uint16_t>(params.skin_voxels + 1);
  const PixelPlane<std::uint16_t> depth = detail::chessboard_depth(inside, cap);
  InsideMask core(fractions.width_px(), fractions.height_px(), 0);
  for (int y = 0; y < fractions.height_px(); ++y) {
    for (int x = 0; x < fractions.width_px(); ++x) core.at(x, y) = depth.at(x, y) == cap ? 1 : 0;
  }
  dither_core(fractions, core, params, layer, labels);
  for (int y = 0; y < fractions.height_px(); ++y) {
    for (int x = 0; x < fractions.width_px(); ++x) {
      const std::uint16_t d = depth.at(x, y);
      if (d > 0 && d < cap) labels.at(x, y) = nearest_pure_label(fractions.pixel(x, y));
    }
  }
}

}  // namespace

void dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params, LabelImage& labels,
            int layer) {
  dither_grid(fractions, inside, params, labels, layer, true);
}

void detail::dither_checked_grid(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params,
                                 LabelImage& labels, int layer) {
  dither_grid(fractions, inside, params, labels, layer, false);
}

LabelImage dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params, int layer) {
  LabelImage labels;
  dither(fractions, inside, params, labels, layer);
  return labels;
}

}  // namespace trivox
