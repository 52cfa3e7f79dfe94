// Nearest-neighbour resampling of label images onto square pixels, shared by the preview
// outputs: a person looks at a layer at its true proportions (a 600 x 300 dpi pixel is twice
// as tall as it is wide), and the result depends only on the labels.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace trivox::detail {

// Samples of pitch `target` that cover n source samples of pitch `pitch` (at least one).
inline int resampled_count(int n, double pitch, double target) {
  return std::max(1, static_cast<int>(std::lround(n * pitch / target)));
}

// Source index of target sample i of m, for n source samples (nearest at the sample centre).
inline int source_index(int i, int m, int n) {
  return std::min(n - 1,
                  static_cast<int>((static_cast<std::int64_t>(2 * i + 1) * n) / (2 * static_cast<std::int64_t>(m))));
}

}  // namespace trivox::detail
