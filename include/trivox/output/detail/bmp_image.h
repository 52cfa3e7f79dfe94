// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Reading the 1-bit BMP files of the "legacy" output (layer_writer.h, docs/FORMATS.md,
// "Legacy bitmap method"), for `trivox verify` and for tests: uncompressed Windows bitmaps
// with a BITMAPINFOHEADER (or a later header that extends it), one bit per pixel, rows
// bottom-up or top-down and padded to 4 bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace trivox {

struct Bmp1Image {
  int width_px = 0;
  int height_px = 0;
  std::vector<std::uint8_t> bits;        // palette index (0 or 1) per pixel, row-major, top row first
  std::uint32_t pixels_per_metre_x = 0;  // the resolution fields
  std::uint32_t pixels_per_metre_y = 0;
};

// Decodes every row of the bitmap. Throws IoError naming `what` and the field at fault when
// the bytes are not such a bitmap: a wrong tag or size field, another bit depth, compression,
// a palette or pixel array that does not fit the file.
Bmp1Image decode_bmp1(std::string_view bytes, const std::string& what);
// The same for a file; IoError names it, also when it cannot be read.
Bmp1Image read_bmp1(const std::filesystem::path& path);

}  // namespace trivox
