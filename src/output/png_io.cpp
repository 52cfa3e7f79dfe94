#include "trivox/output/png_io.h"

#include <fmt/format.h>
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <system_error>

#include "trivox/error.h"
#include "trivox/output/atomic_file.h"

namespace trivox {

std::string_view to_string(PngFilter filter) noexcept {
  switch (filter) {
    case PngFilter::kNone: return "none";
    case PngFilter::kSub: return "sub";
    case PngFilter::kUp: return "up";
    case PngFilter::kAverage: return "average";
    case PngFilter::kPaeth: return "paeth";
    case PngFilter::kAdaptive: return "adaptive";
  }
  return "unknown";
}

std::string_view to_string(PngStrategy strategy) noexcept {
  switch (strategy) {
    case PngStrategy::kDefault: return "default";
    case PngStrategy::kFiltered: return "filtered";
    case PngStrategy::kRle: return "rle";
    case PngStrategy::kHuffmanOnly: return "huffman-only";
  }
  return "unknown";
}

namespace {

// zlib's constant for a strategy; -1 for a value outside the enumeration.
int zlib_strategy(PngStrategy strategy) noexcept {
  switch (strategy) {
    case PngStrategy::kDefault: return Z_DEFAULT_STRATEGY;
    case PngStrategy::kFiltered: return Z_FILTERED;
    case PngStrategy::kRle: return Z_RLE;
    case PngStrategy::kHuffmanOnly: return Z_HUFFMAN_ONLY;
  }
  return -1;
}

// libpng's bit mask for a filter choice; 0 for a value outside the enumeration.
int png_filter_mask(PngFilter filter) noexcept {
  switch (filter) {
    case PngFilter::kNone: return PNG_FILTER_NONE;
    case PngFilter::kSub: return PNG_FILTER_SUB;
    case PngFilter::kUp: return PNG_FILTER_UP;
    case PngFilter::kAverage: return PNG_FILTER_AVG;
    case PngFilter::kPaeth: return PNG_FILTER_PAETH;
    case PngFilter::kAdaptive: return PNG_ALL_FILTERS;
  }
  return 0;
}

std::string errno_text(int error_number) { return std::error_code(error_number, std::generic_category()).message(); }

// ---- libpng calls ------------------------------------------------------------------------
//
// libpng reports errors by calling our error function, which must not return: it records
// the message and longjmps back to the setjmp in the *_core function. Throwing a C++
// exception through libpng's C frames would be undefined, and a longjmp that skips a
// non-trivial destructor is too ([csetjmp.syn]); so the core functions and the callbacks
// hold only plain data, and every C++ object (vectors, files, paths) lives in their callers,
// which longjmp never crosses. The core functions report failure by returning false.

struct PngMessage {
  char text[256];
};

[[noreturn]] void on_png_error(png_structp png, png_const_charp message) {
  auto* out = static_cast<PngMessage*>(png_get_error_ptr(png));
  std::snprintf(out->text, sizeof out->text, "%s", message != nullptr ? message : "error");
  png_longjmp(png, 1);
}

// The library never prints; libpng's default handler would write warnings to stderr.
void on_png_warning(png_structp, png_const_charp) {}

// The rows of a job written a row at a time: `fill` fills `row` (owned by the caller).
struct PngRowSource {
  const std::function<void(int, std::span<std::uint8_t>)>* fill;
  std::uint8_t* row;
  std::size_t row_bytes;
};

struct PngWriteJob {
  std::FILE* file;
  const unsigned char* pixels;  // null when `rows` supplies the pixels
  const PngRowSource* rows;
  std::size_t row_stride;  // bytes from one row to the next
  png_uint_32 width;
  png_uint_32 height;
  int bit_depth;
  int color_type;
  int zlib_level;
  int zlib_strategy;
  int filter_mask;
  const png_color* palette;  // colour type 3: PLTE entries (owned by the caller)
  int palette_size;
  png_uint_32 ppm_x, ppm_y;  // pHYs, pixels per metre; 0: none
  PngMessage error;
};

bool write_png_core(PngWriteJob* job) noexcept {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job->error, on_png_error, on_png_warning);
  if (png == nullptr) {
    std::snprintf(job->error.text, sizeof job->error.text, "cannot create a libpng writer");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(job->error.text, sizeof job->error.text, "cannot create a libpng info");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, job->file);
  png_set_compression_level(png, job->zlib_level);
  png_set_compression_strategy(png, job->zlib_strategy);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, job->filter_mask);
  png_set_IHDR(png, info, job->width, job->height, job->bit_depth, job->color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  if (job->palette_size > 0) png_set_PLTE(png, info, job->palette, job->palette_size);
  if (job->ppm_x > 0 && job->ppm_y > 0) png_set_pHYs(png, info, job->ppm_x, job->ppm_y, PNG_RESOLUTION_METER);
  png_write_info(png, info);
  for (png_uint_32 y = 0; y < job->height; ++y) {
    if (job->rows == nullptr) {
      png_write_row(png, job->pixels + static_cast<std::size_t>(y) * job->row_stride);
      continue;
    }
    // The row source runs here, in this frame, not inside libpng: its exception is caught
    // before any longjmp could skip it.
    bool filled = true;
    try {
      (*job->rows->fill)(static_cast<int>(y), {job->rows->row, job->rows->row_bytes});
    } catch (const std::exception& e) {
      std::snprintf(job->error.text, sizeof job->error.text, "%s", e.what());
      filled = false;
    } catch (...) {
      std::snprintf(job->error.text, sizeof job->error.text, "the row source failed");
      filled = false;
    }
    if (!filled) {
      png_destroy_write_struct(&png, &info);
      return false;
    }
    png_write_row(png, job->rows->row);
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

// Resizes from inside read_png_core: completes before any longjmp and never throws.
bool resize_pixels(std::vector<std::uint8_t>* pixels, std::size_t size) noexcept {
  try {
    pixels->resize(size);
    return true;
  } catch (...) {
    return false;
  }
}

struct PngReadJob {
  std::FILE* file;
  std::vector<std::uint8_t>* rgba;  // owned by the caller
  png_uint_32 width;
  png_uint_32 height;
  PngMessage error;
};

bool read_png_core(PngReadJob* job) noexcept {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job->error, on_png_error, on_png_warning);
  if (png == nullptr) {
    std::snprintf(job->error.text, sizeof job->error.text, "cannot create a libpng reader");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(job->error.text, sizeof job->error.text, "cannot create a libpng info");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_init_io(png, job->file);
  png_read_info(png, info);
  job->width = png_get_image_width(png, info);
  job->height = png_get_image_height(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  const int color_type = png_get_color_type(png, info);
  const bool has_trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;

  // Transformations to 8-bit RGBA, with no gamma handling so that values come back as stored.
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (has_trns) png_set_tRNS_to_alpha(png);
  if (bit_depth == 16) png_set_scale_16(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_ALPHA) == 0 && !has_trns) {
    png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  }
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);

  const std::size_t row_bytes = static_cast<std::size_t>(job->width) * 4;
  if (png_get_rowbytes(png, info) != row_bytes) png_error(png, "cannot convert to 8-bit RGBA");
  if (!resize_pixels(job->rgba, row_bytes * job->height)) png_error(png, "out of memory");
  unsigned char* data = job->rgba->data();
  for (int pass = 0; pass < passes; ++pass) {
    for (png_uint_32 y = 0; y < job->height; ++y) {
      png_read_row(png, data + static_cast<std::size_t>(y) * row_bytes, nullptr);
    }
  }
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

// libpng refuses images wider or taller than this unless told otherwise (png_set_user_limits);
// a slice at 300 dpi that large would be 85 m long.
constexpr int kMaxPngSidePx = 1000000;

void check_size(const std::filesystem::path& path, int width_px, int height_px, std::size_t bytes_per_pixel,
                std::size_t given) {
  if (width_px < 1 || height_px < 1 || width_px > kMaxPngSidePx || height_px > kMaxPngSidePx) {
    throw Error(fmt::format("{}: PNG size {} x {} px is not within 1..{} per side", path.string(), width_px, height_px,
                            kMaxPngSidePx));
  }
  const std::size_t expected =
      static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px) * bytes_per_pixel;
  if (given != expected) {
    throw Error(fmt::format("{}: {} x {} px needs {} bytes of pixels, got {}", path.string(), width_px, height_px,
                            expected, given));
  }
}

void write_png(const std::filesystem::path& path, const PngWriteParams& params, PngWriteJob job) {
  AtomicFile temp(path);
  job.file = temp.file();
  job.zlib_level = params.zlib_level;
  job.zlib_strategy = zlib_strategy(params.strategy);
  job.filter_mask = png_filter_mask(params.filter);
  job.ppm_x = params.pixels_per_metre_x;
  job.ppm_y = params.pixels_per_metre_y;
  job.error.text[0] = '\0';
  errno = 0;
  if (!write_png_core(&job)) {
    // libpng's own text for a failed fwrite is just "Write Error"; errno says why.
    const int error_number = errno;
    throw IoError(fmt::format("{}: cannot write PNG: {}{}", path.string(), job.error.text,
                              error_number != 0 ? " (" + errno_text(error_number) + ")" : ""));
  }
  temp.commit();
}

PngWriteJob make_job(const unsigned char* pixels, std::size_t row_stride, int width_px, int height_px, int bit_depth,
                     int color_type) {
  PngWriteJob job{};
  job.pixels = pixels;
  job.row_stride = row_stride;
  job.width = static_cast<png_uint_32>(width_px);
  job.height = static_cast<png_uint_32>(height_px);
  job.bit_depth = bit_depth;
  job.color_type = color_type;
  return job;
}

}  // namespace

void PngWriteParams::validate() const {
  if (zlib_level < 0 || zlib_level > 9) {
    throw Error(fmt::format("png params: zlib_level = {} is outside [0, 9]", zlib_level));
  }
  if (png_filter_mask(filter) == 0) {
    throw Error(fmt::format("png params: filter = {} is not a known PNG filter", static_cast<int>(filter)));
  }
  if (zlib_strategy(strategy) < 0) {
    throw Error(fmt::format("png params: strategy = {} is not a known zlib strategy", static_cast<int>(strategy)));
  }
  if ((pixels_per_metre_x == 0) != (pixels_per_metre_y == 0)) {
    throw Error(fmt::format("png params: pHYs needs both densities or neither, got {} x {} pixels per metre",
                            pixels_per_metre_x, pixels_per_metre_y));
  }
}

std::uint32_t pixels_per_metre(double pitch_mm) {
  if (!(pitch_mm > 0) || !std::isfinite(pitch_mm))
    throw Error(fmt::format("png params: a pixel pitch of {} mm has no density", pitch_mm));
  const double ppm = std::round(1000.0 / pitch_mm);
  if (ppm < 1 || ppm > 2147483647.0)
    throw Error(fmt::format("png params: {} pixels per metre (pitch {} mm) is outside pHYs's range", ppm, pitch_mm));
  return static_cast<std::uint32_t>(ppm);
}

void write_png_rgba(const std::filesystem::path& path, int width_px, int height_px, std::span<const std::uint8_t> rgba,
                    const PngWriteParams& params) {
  params.validate();
  check_size(path, width_px, height_px, 4, rgba.size());
  write_png(path, params,
            make_job(rgba.data(), static_cast<std::size_t>(width_px) * 4, width_px, height_px, 8, PNG_COLOR_TYPE_RGBA));
}

void write_png_rgba_rows(const std::filesystem::path& path, int width_px, int height_px,
                         const std::function<void(int y, std::span<std::uint8_t> row)>& fill_row,
                         const PngWriteParams& params) {
  params.validate();
  const std::size_t row_bytes = static_cast<std::size_t>(std::max(width_px, 0)) * 4;
  check_size(path, width_px, height_px, 4, row_bytes * static_cast<std::size_t>(std::max(height_px, 0)));
  std::vector<std::uint8_t> row(row_bytes);
  const PngRowSource rows{&fill_row, row.data(), row_bytes};
  PngWriteJob job = make_job(nullptr, row_bytes, width_px, height_px, 8, PNG_COLOR_TYPE_RGBA);
  job.rows = &rows;
  write_png(path, params, job);
}

void write_png_rgba(const std::filesystem::path& path, const RgbaImage& image, const PngWriteParams& params) {
  write_png_rgba(path, image.width_px, image.height_px, image.rgba, params);
}

namespace {

// The bytes of a PNG written by write_png_core into a memory stream: those of the file.
std::string encode_png(const PngWriteParams& params, PngWriteJob job) {
  const std::filesystem::path what("<PNG in memory>");
  char* buffer = nullptr;
  std::size_t size = 0;
  std::FILE* stream = ::open_memstream(&buffer, &size);
  if (stream == nullptr)
    throw IoError(fmt::format("{}: cannot open a memory stream: {}", what.string(), errno_text(errno)));
  job.file = stream;
  job.zlib_level = params.zlib_level;
  job.zlib_strategy = zlib_strategy(params.strategy);
  job.filter_mask = png_filter_mask(params.filter);
  job.ppm_x = params.pixels_per_metre_x;
  job.ppm_y = params.pixels_per_metre_y;
  job.error.text[0] = '\0';
  const bool ok = write_png_core(&job);
  const bool closed = std::fclose(stream) == 0;
  std::string bytes;
  if (ok && closed && buffer != nullptr) bytes.assign(buffer, size);
  std::free(buffer);
  if (!ok || !closed) throw IoError(fmt::format("{}: cannot encode PNG: {}", what.string(), job.error.text));
  return bytes;
}

}  // namespace

std::string encode_png_rgba(int width_px, int height_px, std::span<const std::uint8_t> rgba,
                            const PngWriteParams& params) {
  params.validate();
  check_size("<PNG in memory>", width_px, height_px, 4, rgba.size());
  return encode_png(params, make_job(rgba.data(), static_cast<std::size_t>(width_px) * 4, width_px, height_px, 8,
                                     PNG_COLOR_TYPE_RGBA));
}

std::string encode_png_gray8(int width_px, int height_px, std::span<const std::uint8_t> gray,
                             const PngWriteParams& params) {
  params.validate();
  check_size("<PNG in memory>", width_px, height_px, 1, gray.size());
  return encode_png(
      params, make_job(gray.data(), static_cast<std::size_t>(width_px), width_px, height_px, 8, PNG_COLOR_TYPE_GRAY));
}

void write_png_indexed(const std::filesystem::path& path, int width_px, int height_px,
                       std::span<const std::uint8_t> indices, std::span<const std::array<std::uint8_t, 3>> palette,
                       const PngWriteParams& params) {
  params.validate();
  check_size(path, width_px, height_px, 1, indices.size());
  if (palette.empty() || palette.size() > 256)
    throw Error(
        fmt::format("{}: an indexed PNG takes 1 to 256 palette colours, not {}", path.string(), palette.size()));
  const int bits = palette.size() <= 2 ? 1 : palette.size() <= 4 ? 2 : palette.size() <= 16 ? 4 : 8;
  // PNG packs pixels narrower than a byte leftmost first, in the most significant bits.
  const std::size_t width = static_cast<std::size_t>(width_px);
  const std::size_t per_byte = static_cast<std::size_t>(8 / bits);
  const std::size_t stride = (width + per_byte - 1) / per_byte;
  std::vector<std::uint8_t> packed(stride * static_cast<std::size_t>(height_px), 0);
  for (std::size_t y = 0; y < static_cast<std::size_t>(height_px); ++y) {
    const std::uint8_t* in = indices.data() + y * width;
    std::uint8_t* out = packed.data() + y * stride;
    for (std::size_t x = 0; x < width; ++x) {
      if (in[x] >= palette.size())
        throw Error(fmt::format("{}: pixel ({}, {}) has palette index {}, beyond the palette's {} colours",
                                path.string(), x, y, in[x], palette.size()));
      const unsigned shift = static_cast<unsigned>(8 - bits) - static_cast<unsigned>((x % per_byte) * bits);
      out[x / per_byte] = static_cast<std::uint8_t>(out[x / per_byte] | (in[x] << shift));
    }
  }
  std::vector<png_color> plte;
  for (const auto& c : palette) plte.push_back({c[0], c[1], c[2]});
  PngWriteJob job = make_job(packed.data(), stride, width_px, height_px, bits, PNG_COLOR_TYPE_PALETTE);
  job.palette = plte.data();
  job.palette_size = static_cast<int>(plte.size());
  write_png(path, params, job);
}

void write_png_gray8(const std::filesystem::path& path, int width_px, int height_px, std::span<const std::uint8_t> gray,
                     const PngWriteParams& params) {
  params.validate();
  check_size(path, width_px, height_px, 1, gray.size());
  write_png(path, params,
            make_job(gray.data(), static_cast<std::size_t>(width_px), width_px, height_px, 8, PNG_COLOR_TYPE_GRAY));
}

void write_png_gray1(const std::filesystem::path& path, int width_px, int height_px,
                     std::span<const std::uint8_t> values, const PngWriteParams& params) {
  params.validate();
  check_size(path, width_px, height_px, 1, values.size());
  // PNG packs 1-bit pixels eight to a byte, leftmost pixel in the most significant bit.
  const std::size_t width = static_cast<std::size_t>(width_px);
  const std::size_t stride = (width + 7) / 8;
  std::vector<std::uint8_t> packed(stride * static_cast<std::size_t>(height_px), 0);
  for (std::size_t y = 0; y < static_cast<std::size_t>(height_px); ++y) {
    const std::uint8_t* in = values.data() + y * width;
    std::uint8_t* out = packed.data() + y * stride;
    for (std::size_t x = 0; x < width; ++x) {
      if (in[x] != 0) out[x / 8] = static_cast<std::uint8_t>(out[x / 8] | (0x80u >> (x % 8)));
    }
  }
  write_png(path, params, make_job(packed.data(), stride, width_px, height_px, 1, PNG_COLOR_TYPE_GRAY));
}

RgbaImage read_png_rgba(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw IoError(fmt::format("{}: cannot open: {}", path.string(), errno_text(errno)));
  }
  RgbaImage image;
  PngReadJob job{};
  job.file = file;
  job.rgba = &image.rgba;
  const bool ok = read_png_core(&job);
  std::fclose(file);
  if (!ok) throw IoError(fmt::format("{}: not a readable PNG: {}", path.string(), job.error.text));
  image.width_px = static_cast<int>(job.width);
  image.height_px = static_cast<int>(job.height);
  return image;
}

RgbaImage decode_png_rgba(std::string_view bytes, const std::string& what) {
  if (bytes.empty()) throw IoError(fmt::format("{}: not a readable PNG: no bytes", what));
  // A read-only stream over the bytes: the same reader as for files.
  std::FILE* stream = ::fmemopen(const_cast<char*>(bytes.data()), bytes.size(), "rb");
  if (stream == nullptr) throw IoError(fmt::format("{}: cannot open a memory stream: {}", what, errno_text(errno)));
  RgbaImage image;
  PngReadJob job{};
  job.file = stream;
  job.rgba = &image.rgba;
  const bool ok = read_png_core(&job);
  std::fclose(stream);
  if (!ok) throw IoError(fmt::format("{}: not a readable PNG: {}", what, job.error.text));
  image.width_px = static_cast<int>(job.width);
  image.height_px = static_cast<int>(job.height);
  return image;
}

}  // namespace trivox
