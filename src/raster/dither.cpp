#include "trivox/raster/dither.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "raster/dither_kernels.h"

namespace trivox {

std::string_view to_string(DiffusionKernel kernel) noexcept {
  switch (kernel) {
    case DiffusionKernel::kFloydSteinberg:
      return "floyd-steinberg";
  }
  return "unknown";
}

void DitherParams::validate() const {
  if (detail::diffusion_taps(kernel).empty()) {
    throw Error(fmt::format("dither params: kernel = {} is not a known diffusion kernel",
                            static_cast<int>(kernel)));
  }
  if (!std::isfinite(fraction_tolerance) || fraction_tolerance < 0.0f ||
      fraction_tolerance >= 0.5f) {
    throw Error(fmt::format("dither params: fraction_tolerance = {} is not in [0, 0.5)",
                            fraction_tolerance));
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
inline void spread_all(const std::int32_t* e, std::size_t num_components,
                       std::int32_t* const* to) noexcept {
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

// Error rows live in a ring of Kernel::kRows rows, each width_px * (m + 1) int32: row y + r
// is slot (y + r) % kRows. After row y is done its slot is cleared and becomes row
// y + kRows.
template <class Kernel>
void dither_with(const MaterialGrid& fractions, const InsideMask& inside, bool serpentine,
                 LabelImage& labels) {
  constexpr auto& taps = Kernel::kTaps;
  constexpr int kNumTaps = static_cast<int>(taps.size());
  constexpr int kRows = Kernel::kRows;

  const int width = fractions.width_px();
  const int height = fractions.height_px();
  const std::size_t m = static_cast<std::size_t>(fractions.num_materials());
  const std::size_t num_components = m + 1;
  const std::size_t row_values = static_cast<std::size_t>(width) * num_components;
  std::vector<std::int32_t> error(static_cast<std::size_t>(kRows) * row_values, 0);

  for (int y = 0; y < height; ++y) {
    const bool reverse = serpentine && (y % 2 == 1);
    const int dir = reverse ? -1 : 1;
    std::int32_t* error_rows[kRows];
    const std::uint8_t* mask_rows[kRows];
    for (int r = 0; r < kRows; ++r) {
      error_rows[r] = error.data() + static_cast<std::size_t>((y + r) % kRows) * row_values;
      mask_rows[r] = y + r < height ? inside.row(y + r).data() : nullptr;
    }
    const float* fraction_row = fractions.row(y).data();
    std::uint8_t* label_row = labels.row(y).data();

    for (int i = 0; i < width; ++i) {
      const int x = reverse ? width - 1 - i : i;
      if (mask_rows[0][x] == 0) {
        label_row[x] = LabelImage::kVoid;
        continue;
      }
      // Desired vector, in place over the error received so far.
      std::int32_t* desired = error_rows[0] + static_cast<std::size_t>(x) * num_components;
      const float* f = fraction_row + static_cast<std::size_t>(x) * m;
      std::int32_t material_total = 0;
      for (std::size_t k = 0; k < m; ++k) {
        const std::int32_t q = detail::fraction_to_fixed(f[k]);
        desired[k + 1] += q;
        material_total += q;
      }
      desired[0] += kDitherFixedOne - material_total;

      // Branch-free running maximum: which component wins is data-dependent noise, the
      // worst case for a branch predictor.
      std::size_t best = 0;
      std::int32_t best_value = desired[0];
      for (std::size_t c = 1; c < num_components; ++c) {
        const bool larger = desired[c] > best_value;
        best = larger ? c : best;
        best_value = larger ? desired[c] : best_value;
      }
      label_row[x] = static_cast<std::uint8_t>(best);
      desired[best] -= kDitherFixedOne;  // now the error to diffuse

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
      if (count == kNumTaps) {
        spread_all<Kernel>(desired, num_components, to);
      } else if (count > 0) {
        spread(desired, num_components, to, weights, count, weight_sum);
      }
    }
    std::fill(error_rows[0], error_rows[0] + row_values, 0);
  }
}

}  // namespace

void dither(const MaterialGrid& fractions, const InsideMask& inside, const DitherParams& params,
            LabelImage& labels) {
  params.validate();
  if (inside.width_px() != fractions.width_px() || inside.height_px() != fractions.height_px()) {
    throw Error(fmt::format("dither: inside mask is {} x {} px but the material grid is {} x {}",
                            inside.width_px(), inside.height_px(), fractions.width_px(),
                            fractions.height_px()));
  }
  fractions.check_fractions(params.fraction_tolerance);
  if (labels.width_px() != fractions.width_px() || labels.height_px() != fractions.height_px()) {
    labels = LabelImage(fractions.width_px(), fractions.height_px());
  }
  switch (params.kernel) {
    case DiffusionKernel::kFloydSteinberg:
      dither_with<detail::FloydSteinbergKernel>(fractions, inside, params.serpentine, labels);
      return;
  }
}

LabelImage dither(const MaterialGrid& fractions, const InsideMask& inside,
                  const DitherParams& params) {
  LabelImage labels;
  dither(fractions, inside, params, labels);
  return labels;
}

}  // namespace trivox
