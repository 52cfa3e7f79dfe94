#include <cerrno>
#include <fstream>
#include <iterator>
#include <system_error>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/output/detail/bmp_image.h"

namespace trivox {

namespace {

std::uint32_t u16(std::string_view b, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at]) | (static_cast<unsigned char>(b[at + 1]) << 8));
}
std::uint32_t u32(std::string_view b, std::size_t at) { return u16(b, at) | (u16(b, at + 2) << 16); }

// A side of at most this many pixels: as for PNG (png_io.cpp), far beyond any printer.
constexpr std::int64_t kMaxSidePx = 1000000;

}  // namespace

Bmp1Image decode_bmp1(std::string_view b, const std::string& what) {
  if (b.size() < 14 + 40 || b[0] != 'B' || b[1] != 'M')
    throw IoError(fmt::format("{}: not a BMP file (no 'BM' tag and headers)", what));
  if (u32(b, 2) != b.size())
    throw IoError(fmt::format("{}: BMP header says {} bytes, the file has {}", what, u32(b, 2), b.size()));
  const std::uint32_t offset = u32(b, 10), header = u32(b, 14);
  if (header < 40 || 14 + static_cast<std::uint64_t>(header) > b.size())
    throw IoError(fmt::format("{}: BMP info header of {} bytes is not a BITMAPINFOHEADER", what, header));
  const auto width = static_cast<std::int32_t>(u32(b, 18)), height = static_cast<std::int32_t>(u32(b, 22));
  const std::uint32_t planes = u16(b, 26), bpp = u16(b, 28), compression = u32(b, 30), colours = u32(b, 46);
  if (planes != 1 || bpp != 1)
    throw IoError(fmt::format("{}: BMP has {} planes of {} bits per pixel, not one plane of 1 bit", what, planes, bpp));
  if (compression != 0)
    throw IoError(fmt::format("{}: BMP compression {} is not BI_RGB (uncompressed)", what, compression));
  const std::int64_t rows = height < 0 ? -static_cast<std::int64_t>(height) : height;
  if (width < 1 || width > kMaxSidePx || rows < 1 || rows > kMaxSidePx)
    throw IoError(fmt::format("{}: BMP size {} x {} px is not within 1..{} per side", what, width, height, kMaxSidePx));
  const std::uint64_t palette_entries = colours == 0 ? 2 : colours;
  if (palette_entries > 2)
    throw IoError(fmt::format("{}: BMP palette of {} colours for 1 bit per pixel", what, colours));
  if (offset < 14 + static_cast<std::uint64_t>(header) + 4 * palette_entries)
    throw IoError(fmt::format("{}: BMP pixel offset {} overlaps the headers and the palette", what, offset));
  const std::uint64_t stride = (static_cast<std::uint64_t>(width) + 31) / 32 * 4;
  if (offset > b.size() || stride * static_cast<std::uint64_t>(rows) > b.size() - offset)
    throw IoError(
        fmt::format("{}: BMP pixel data ({} rows of {} bytes from byte {}) does not fit the {} bytes of the file", what,
                    rows, stride, offset, b.size()));
  Bmp1Image im;
  im.width_px = width;
  im.height_px = static_cast<int>(rows);
  im.pixels_per_metre_x = u32(b, 38);
  im.pixels_per_metre_y = u32(b, 42);
  im.bits.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(rows));
  for (std::int64_t y = 0; y < rows; ++y) {
    // A positive height stores the bottom row first.
    const std::int64_t stored = height > 0 ? rows - 1 - y : y;
    const std::size_t row_at = offset + static_cast<std::size_t>(stored) * stride;
    std::uint8_t* out = im.bits.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
    for (std::int32_t x = 0; x < width; ++x)
      out[x] = static_cast<std::uint8_t>(
          (static_cast<unsigned char>(b[row_at + static_cast<std::size_t>(x / 8)]) >> (7 - x % 8)) & 1u);
  }
  return im;
}

Bmp1Image read_bmp1(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IoError(
        fmt::format("{}: cannot open: {}", path.string(), std::error_code(errno, std::generic_category()).message()));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(fmt::format("{}: cannot read", path.string()));
  return decode_bmp1(bytes, path.string());
}

}  // namespace trivox
