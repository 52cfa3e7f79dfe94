// Writers of the registry (layer_writer.h) that live in their own files: the stack outputs
// and the legacy bitmap method.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "trivox/output/layer_writer.h"

namespace trivox::detail {

// "preview": contact sheet and three orthogonal cuts (preview_writer.cpp).
std::unique_ptr<LayerWriter> make_preview_writer(const OutputContext& context);

// "tiff": every layer as a page of tiff/stack.tif (tiff_stack_writer.cpp).
std::unique_ptr<LayerWriter> make_tiff_stack_writer(const OutputContext& context);

// "vdb": one OpenVDB grid per material in vdb/stack.vdb (vdb_writer.cpp).
std::unique_ptr<LayerWriter> make_vdb_writer(const OutputContext& context);

// "gcvf": the Voxel Print PNGs and ConfigFile.xml zipped into gcvf/stack.gcvf (gcvf_writer.cpp).
std::unique_ptr<LayerWriter> make_gcvf_writer(const OutputContext& context);

// "greyscale": one 8-bit greyscale PNG per layer with pHYs (greyscale_writers.cpp).
std::unique_ptr<LayerWriter> make_greyscale_stack_writer(const OutputContext& context);
// "sl1", "sl1s": a Prusa SL1 / SL1S print archive (greyscale_writers.cpp).
std::unique_ptr<LayerWriter> make_sl1_writer(const OutputContext& context);
std::unique_ptr<LayerWriter> make_sl1s_writer(const OutputContext& context);

// The job's PNG settings with the layer's pixel size as a pHYs chunk (pixels per metre from
// the printer's pitch: 600 x 300 dpi is 23622 x 11811), so that viewers show a printer
// image at its true proportions. Used by the per-layer printer images (Voxel Print, the
// material bitmaps, the greyscale stack) and the package's PNGs.
PngWriteParams png_with_pixel_size(const OutputContext& context);

// An opaque copy of a colour (alpha 255).
std::array<std::uint8_t, 4> opaque(std::array<std::uint8_t, 4> rgba);
// The Voxel Print colour of every label (index = label: the background, then the materials).
// Every colour is opaque (alpha 255; a material's alpha is for previews). Throws Error unless
// every material and the background have distinct colours.
std::vector<std::array<std::uint8_t, 4>> voxelprint_palette(const OutputContext& context);
// The 8-bit RGBA pixels of `labels` in `palette`'s colours, row-major, top row first.
std::vector<std::uint8_t> voxelprint_rgba(const LabelImage& labels,
                                          const std::vector<std::array<std::uint8_t, 4>>& palette);
// The same for row y alone, into `rgba` (labels.width_px() * 4 bytes).
void voxelprint_rgba_row(const LabelImage& labels, int y, const std::vector<std::array<std::uint8_t, 4>>& palette,
                         std::span<std::uint8_t> rgba);

// "legacy": 1-bit BMP per material per layer and legacy/slices.txt (legacy_bitmap_writer.cpp).
std::unique_ptr<LayerWriter> make_legacy_bitmap_writer(const OutputContext& context);

// A 1-bit uncompressed BMP (BITMAPINFOHEADER, rows bottom-up, palette black/white): one byte
// per pixel in `bits` (row-major, top row first), nonzero = white = 1.
std::string encode_bmp1(int width_px, int height_px, const std::uint8_t* bits, double pitch_x_mm, double pitch_y_mm);

}  // namespace trivox::detail
