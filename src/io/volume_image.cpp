#include "trivox/io/detail/volume_image.h"

#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

void VolumeImage::validate() const {
  if (nx < 1 || ny < 1 || nz < 1)
    throw Error(fmt::format("volume image: size {} x {} x {} is not at least 1 x 1 x 1", nx, ny, nz));
  if (channels < 1 || channels > 64) throw Error(fmt::format("volume image: {} channels is not in [1, 64]", channels));
  const auto expected = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz) *
                        static_cast<std::size_t>(channels);
  if (values.size() != expected)
    throw Error(
        fmt::format("volume image: {} values for {} x {} x {} x {} channels", values.size(), nx, ny, nz, channels));
  for (float v : values)
    if (!std::isfinite(v)) throw Error("volume image: a value is not a finite number");
}

namespace {

std::size_t sample_bytes(RawSampleType type) {
  switch (type) {
    case RawSampleType::kUint8: return 1;
    case RawSampleType::kUint16: return 2;
    case RawSampleType::kFloat32: return 4;
  }
  return 0;
}

// An unsigned value of `bytes` bytes at p, in the given byte order.
std::uint32_t load_unsigned(const unsigned char* p, std::size_t bytes, bool big_endian) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < bytes; ++i) {
    const std::size_t k = big_endian ? i : bytes - 1 - i;
    v = (v << 8) | p[k];
  }
  return v;
}

}  // namespace

VolumeImage read_raw_volume(const std::filesystem::path& path, const RawVolumeLayout& layout) {
  VolumeImage image;
  image.nx = layout.nx;
  image.ny = layout.ny;
  image.nz = layout.nz;
  image.channels = layout.channels;
  const std::string file = path.string();
  if (layout.nx < 1 || layout.ny < 1 || layout.nz < 1 || layout.channels < 1 || layout.channels > 64)
    throw InputError(file, 0, "",
                     fmt::format("the declared size {} x {} x {} x {} channels is not valid", layout.nx, layout.ny,
                                 layout.nz, layout.channels));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open the raw volume", file));
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(fmt::format("{}: cannot read the raw volume", file));
  const std::size_t count = static_cast<std::size_t>(layout.nx) * static_cast<std::size_t>(layout.ny) *
                            static_cast<std::size_t>(layout.nz) * static_cast<std::size_t>(layout.channels);
  const std::size_t size = sample_bytes(layout.type);
  if (bytes.size() != count * size)
    throw InputError(file, 0, "",
                     fmt::format("the file holds {} bytes but {} x {} x {} samples of {} channel(s) of {} "
                                 "byte(s) need {}",
                                 bytes.size(), layout.nx, layout.ny, layout.nz, layout.channels, size, count * size));
  image.values.resize(count);
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  for (std::size_t i = 0; i < count; ++i, p += size) {
    const std::uint32_t raw = load_unsigned(p, size, layout.big_endian);
    switch (layout.type) {
      case RawSampleType::kUint8: image.values[i] = static_cast<float>(raw) / 255.0f; break;
      case RawSampleType::kUint16: image.values[i] = static_cast<float>(raw) / 65535.0f; break;
      case RawSampleType::kFloat32: {
        float f;
        std::memcpy(&f, &raw, sizeof f);
        if (!std::isfinite(f)) throw InputError(file, 0, "", fmt::format("sample {} is not a finite number", i));
        image.values[i] = f;
        break;
      }
    }
  }
  return image;
}

namespace {

struct TiffCloser {
  void operator()(TIFF* t) const noexcept { TIFFClose(t); }
};

// libtiff reports through global handlers; while a file is read they are silenced (its
// problems are reported through exceptions) and restored afterwards.
void quiet_handler(const char*, const char*, va_list) {}

class QuietTiff {
 public:
  QuietTiff() : error_(TIFFSetErrorHandler(quiet_handler)), warning_(TIFFSetWarningHandler(quiet_handler)) {}
  ~QuietTiff() {
    TIFFSetErrorHandler(error_);
    TIFFSetWarningHandler(warning_);
  }
  QuietTiff(const QuietTiff&) = delete;
  QuietTiff& operator=(const QuietTiff&) = delete;

 private:
  TIFFErrorHandler error_;
  TIFFErrorHandler warning_;
};

}  // namespace

VolumeImage read_tiff_volume(const std::filesystem::path& path) {
  const std::string file = path.string();
  const QuietTiff quiet;
  std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpen(file.c_str(), "r"));
  if (!tif) throw IoError(fmt::format("{}: cannot open as a TIFF file", file));
  VolumeImage image;
  std::uint16_t first_bits = 0, first_format = 0;
  int page = 0;
  do {
    std::uint32_t w = 0, h = 0;
    std::uint16_t spp = 1, bits = 1, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
    TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &h);
    TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLESPERPIXEL, &spp);
    TIFFGetFieldDefaulted(tif.get(), TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetFieldDefaulted(tif.get(), TIFFTAG_PLANARCONFIG, &planar);
    const std::string where = fmt::format("page {}", page);
    const bool supported =
        (format == SAMPLEFORMAT_UINT && (bits == 8 || bits == 16)) || (format == SAMPLEFORMAT_IEEEFP && bits == 32);
    if (!supported)
      throw UnsupportedError(file, 0, where,
                             fmt::format("{}-bit samples of format {} are not supported (8- or "
                                         "16-bit unsigned, or 32-bit float)",
                                         bits, format));
    if (spp < 1 || spp > 4)
      throw UnsupportedError(file, 0, where, fmt::format("{} samples per pixel (1 to 4 are supported)", spp));
    if (planar != PLANARCONFIG_CONTIG && spp > 1)
      throw UnsupportedError(file, 0, where, "separate colour planes are not supported");
    if (w < 1 || h < 1 || w > (1u << 16) || h > (1u << 16))
      throw InputError(file, 0, where, fmt::format("size {} x {} is not in 1 .. 65536", w, h));
    if (page == 0) {
      image.nx = static_cast<int>(w);
      image.ny = static_cast<int>(h);
      image.channels = spp;
      first_bits = bits;
      first_format = format;
    } else if (static_cast<int>(w) != image.nx || static_cast<int>(h) != image.ny || spp != image.channels ||
               bits != first_bits || format != first_format) {
      throw InputError(file, 0, where,
                       fmt::format("{} x {} px, {} samples of {} bits differ from page 0's {} x {} px, "
                                   "{} samples of {} bits",
                                   w, h, spp, bits, image.nx, image.ny, image.channels, first_bits));
    }
    // Read the page through the strip or tile interface into one buffer of rows.
    const std::size_t row_samples = static_cast<std::size_t>(w) * spp;
    const std::size_t bytes_per_sample = bits / 8u;
    std::vector<unsigned char> pixels(row_samples * h * bytes_per_sample);
    if (TIFFIsTiled(tif.get())) {
      std::uint32_t tw = 0, th = 0;
      TIFFGetField(tif.get(), TIFFTAG_TILEWIDTH, &tw);
      TIFFGetField(tif.get(), TIFFTAG_TILELENGTH, &th);
      std::vector<unsigned char> tile(static_cast<std::size_t>(TIFFTileSize(tif.get())));
      for (std::uint32_t ty = 0; ty < h; ty += th) {
        for (std::uint32_t tx = 0; tx < w; tx += tw) {
          if (TIFFReadTile(tif.get(), tile.data(), tx, ty, 0, 0) < 0)
            throw InputError(file, 0, where, "a tile cannot be decoded");
          for (std::uint32_t y = ty; y < std::min(h, ty + th); ++y) {
            const std::size_t n = static_cast<std::size_t>(std::min(w, tx + tw) - tx) * spp * bytes_per_sample;
            std::memcpy(pixels.data() + (y * row_samples + tx * spp) * bytes_per_sample,
                        tile.data() + static_cast<std::size_t>(y - ty) * tw * spp * bytes_per_sample, n);
          }
        }
      }
    } else {
      std::vector<unsigned char> line(static_cast<std::size_t>(TIFFScanlineSize(tif.get())));
      for (std::uint32_t y = 0; y < h; ++y) {
        if (TIFFReadScanline(tif.get(), line.data(), y, 0) < 0)
          throw InputError(file, 0, where, fmt::format("row {} cannot be decoded", y));
        std::memcpy(pixels.data() + y * row_samples * bytes_per_sample, line.data(), row_samples * bytes_per_sample);
      }
    }
    const std::size_t base = image.values.size();
    image.values.resize(base + row_samples * h);
    for (std::size_t i = 0; i < row_samples * h; ++i) {
      const unsigned char* p = pixels.data() + i * bytes_per_sample;
      float v;
      if (bits == 8) {
        v = static_cast<float>(p[0]) / 255.0f;
      } else if (bits == 16) {
        std::uint16_t u;
        std::memcpy(&u, p, 2);  // libtiff delivers samples in native byte order
        v = static_cast<float>(u) / 65535.0f;
      } else {
        std::memcpy(&v, p, 4);
        if (!std::isfinite(v)) throw InputError(file, 0, where, fmt::format("sample {} is not a finite number", i));
      }
      image.values[base + i] = v;
    }
    ++page;
    if (page > (1 << 16)) throw InputError(file, 0, "", "more than 65536 pages");
  } while (TIFFReadDirectory(tif.get()));
  image.nz = page;
  return image;
}

}  // namespace trivox
