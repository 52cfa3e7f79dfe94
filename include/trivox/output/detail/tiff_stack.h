// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Reading the multi-page TIFF stack the "tiff" output writes (layer_writer.h): one 8-bit
// palette page per job layer, pixel value = label (0 void, 1 + j material j), Adobe Deflate
// compressed (docs/FORMATS.md, "Multi-page TIFF").
#pragma once

#include <filesystem>
#include <functional>

#include "trivox/raster/material_grid.h"

namespace trivox {

// Decodes every page in order and hands it to `visit(page_index, labels)`; returns the
// number of pages. Throws IoError naming the file when it is not a readable 8-bit,
// one-sample TIFF.
int read_tiff_stack(const std::filesystem::path& path, const std::function<void(int, const LabelImage&)>& visit);

}  // namespace trivox
