// PNG files for slices: 32-bit RGBA (the Voxel Print layer format), indexed-colour (the
// previews), 8-bit grayscale and 1-bit grayscale writers, and a reader that turns any PNG into 8-bit RGBA (for tests
// and for verifying what was written).
//
// Pixels are row-major, top row first, no padding between rows; x runs along the image
// width. Writes are atomic: the PNG goes to a temporary file beside the target
// ("<name>.tmp-<pid>-<n>"), is flushed and fsync'ed, then renamed over the target, so a
// killed job never leaves a truncated file under the final name (it may leave the
// temporary one). The bytes written depend only on the pixels, the params and the zlib
// build (no time stamps or text chunks).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trivox {

// PNG row filters (PNG specification, section 9). kAdaptive lets libpng pick one per row.
enum class PngFilter { kNone, kSub, kUp, kAverage, kPaeth, kAdaptive };
std::string_view to_string(PngFilter filter) noexcept;

// zlib's match strategies (zlib.h): kRle looks for runs only (matches at distance 1), which
// after the `sub` filter are the runs of equal pixels a dithered layer consists of.
enum class PngStrategy { kDefault, kFiltered, kRle, kHuffmanOnly };
std::string_view to_string(PngStrategy strategy) noexcept;

struct PngWriteParams {
  // The defaults favour speed: of every setting bench/png_settings_bench times on dithered
  // layers (docs/PERFORMANCE.md, "PNG settings"), level 1 with no filter encodes fastest;
  // the `sub` filter with the `rle` strategy makes files about half as large for about a
  // fifth more time, and higher levels cost more time for little. On a noise-like slice
  // (3 materials, 3040 x 1512, fsync included) level 1 wrote 1.51 MB in 140-165 ms, level 6
  // 0.78 MB in 535-885 ms, level 9 0.68 MB in 8-13 s.
  int zlib_level = 1;  // 0 (store) to 9 (smallest)
  PngFilter filter = PngFilter::kNone;
  PngStrategy strategy = PngStrategy::kDefault;
  // The physical pixel size, written as a pHYs chunk (pixels per metre along x and y, unit
  // metre) when both are nonzero; 0 and 0: no pHYs chunk. pixels_per_metre() converts a pitch.
  std::uint32_t pixels_per_metre_x = 0;
  std::uint32_t pixels_per_metre_y = 0;

  // Throws Error naming the field when zlib_level is outside [0, 9], filter or strategy is
  // unknown, or exactly one of the pHYs densities is 0.
  void validate() const;
};

// Pixels per metre of a pitch in millimetres, rounded to the nearest whole number (pHYs
// stores whole numbers): 0.05 mm is 20000, 600 dpi (0.04233 mm) 23622.
std::uint32_t pixels_per_metre(double pitch_mm);

// An 8-bit RGBA image: width_px * height_px * 4 bytes, R G B A per pixel.
struct RgbaImage {
  int width_px = 0;
  int height_px = 0;
  std::vector<std::uint8_t> rgba;

  bool operator==(const RgbaImage&) const = default;
};

// Writes colour type 6 (RGBA), bit depth 8. `rgba` holds width_px * height_px * 4 bytes.
// Throws Error when a size is not positive or the span's length does not match, IoError
// naming the path when the file cannot be written (the temporary file is then removed).
void write_png_rgba(const std::filesystem::path& path, int width_px, int height_px, std::span<const std::uint8_t> rgba,
                    const PngWriteParams& params = {});
void write_png_rgba(const std::filesystem::path& path, const RgbaImage& image, const PngWriteParams& params = {});

// Writes the same file as write_png_rgba, asking for the pixels a row at a time: `fill_row(y,
// row)` fills row y (width_px * 4 bytes), top row first, so that the whole RGBA image never
// exists in memory. If fill_row throws, nothing is written under `path` and the exception's
// message is reported as an IoError.
void write_png_rgba_rows(const std::filesystem::path& path, int width_px, int height_px,
                         const std::function<void(int y, std::span<std::uint8_t> row)>& fill_row,
                         const PngWriteParams& params = {});

// The bytes write_png_rgba would write, in memory (for outputs that package PNGs).
std::string encode_png_rgba(int width_px, int height_px, std::span<const std::uint8_t> rgba,
                            const PngWriteParams& params = {});

// Writes colour type 3 (indexed colour): one byte per pixel in `indices`, each an index into
// `palette` (1 to 256 opaque RGB colours, written as PLTE). The pixels are packed at the
// smallest bit depth that holds every palette index (1, 2, 4 or 8 bits), so an image of a
// few colours, such as the preview of a dithered layer, takes a fraction of its RGBA size.
// Throws Error when a size is not positive, the span's length does not match, the palette is
// empty or longer than 256, or an index is not below the palette's size; IoError as above.
void write_png_indexed(const std::filesystem::path& path, int width_px, int height_px,
                       std::span<const std::uint8_t> indices, std::span<const std::array<std::uint8_t, 3>> palette,
                       const PngWriteParams& params = {});

// Writes colour type 0 (grayscale), bit depth 8: one byte per pixel.
void write_png_gray8(const std::filesystem::path& path, int width_px, int height_px, std::span<const std::uint8_t> gray,
                     const PngWriteParams& params = {});
// The bytes write_png_gray8 would write, in memory.
std::string encode_png_gray8(int width_px, int height_px, std::span<const std::uint8_t> gray,
                             const PngWriteParams& params = {});

// Writes colour type 0, bit depth 1: one byte per pixel in `values`, nonzero = white (1).
void write_png_gray1(const std::filesystem::path& path, int width_px, int height_px,
                     std::span<const std::uint8_t> values, const PngWriteParams& params = {});

// Reads any PNG (any colour type and bit depth, interlaced or not) as 8-bit RGBA: gray is
// replicated into R, G and B, palette entries are expanded, 16-bit samples are scaled to 8
// bits, and alpha is 255 where the file has none (tRNS is honoured). No gamma or colour
// conversion is applied. Throws IoError naming the path when the file cannot be opened or
// is not a valid PNG.
RgbaImage read_png_rgba(const std::filesystem::path& path);
// The same for the bytes of a PNG in memory (an entry of a package); `what` names them in
// the IoError.
RgbaImage decode_png_rgba(std::string_view bytes, const std::string& what);

}  // namespace trivox
