// The per-material bitmaps of a layer, which the "bitmaps" and "legacy" formats write (one
// 1-bit image per material, PNG or BMP): the one loop that forms them.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "trivox/raster/material_grid.h"

namespace trivox::detail {

// Calls write(j, bits) for each material j < num_materials, bits holding 1 where `labels`
// has material j and 0 elsewhere (row-major, one byte per pixel; reused between calls).
template <class Write>
void for_each_material_bits(const LabelImage& labels, std::size_t num_materials, Write&& write) {
  std::vector<std::uint8_t> bits(labels.values().size());
  for (std::size_t j = 0; j < num_materials; ++j) {
    const auto label = LabelImage::label_of_material(static_cast<int>(j));
    std::transform(labels.values().begin(), labels.values().end(), bits.begin(),
                   [&](std::uint8_t l) { return static_cast<std::uint8_t>(l == label ? 1 : 0); });
    write(j, bits);
  }
}

}  // namespace trivox::detail
