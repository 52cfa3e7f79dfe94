// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Volume images: 3D arrays of samples with one or more channels, the data behind volumetric
// textures (material/detail/volume_texture.h). A 2D image is a volume one slice deep.
//
// Values are stored as float, normalised on reading: unsigned 8- and 16-bit samples are
// divided by 255 and 65535 (so [0, 1]); 32-bit float samples are kept as they are.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

namespace trivox {

struct VolumeImage {
  int nx = 0, ny = 0, nz = 0;  // samples along x (fastest), y, z
  int channels = 1;
  std::vector<float> values;  // index ((z * ny + y) * nx + x) * channels + c

  float at(int x, int y, int z, int c) const noexcept {
    return values[((static_cast<std::size_t>(z) * static_cast<std::size_t>(ny) + static_cast<std::size_t>(y)) *
                       static_cast<std::size_t>(nx) +
                   static_cast<std::size_t>(x)) *
                      static_cast<std::size_t>(channels) +
                  static_cast<std::size_t>(c)];
  }
  // Throws Error unless the sizes are >= 1, channels is 1..64, values has
  // nx * ny * nz * channels entries and every value is finite.
  void validate() const;
};

enum class RawSampleType { kUint8, kUint16, kFloat32 };

// The layout of a headerless raw file: nx * ny * nz samples of `channels` interleaved
// values each, x fastest, then y, then z.
struct RawVolumeLayout {
  int nx = 0, ny = 0, nz = 0;
  int channels = 1;
  RawSampleType type = RawSampleType::kUint8;
  bool big_endian = false;
};

// Reads a raw volume. Throws IoError when the file cannot be read, InputError(file, 0, "",
// rule) when its size differs from what the layout declares or a float is not finite.
VolumeImage read_raw_volume(const std::filesystem::path& path, const RawVolumeLayout& layout);

// Reads a TIFF file, every page (image directory) one z slice, in file order: 8- or 16-bit
// unsigned integer or 32-bit float samples, 1 to 4 samples per pixel (grey, grey + alpha, RGB,
// RGBA), strips or tiles, every page the same size and format. Throws IoError when the file
// cannot be opened, UnsupportedError for other sample formats, InputError for pages that
// disagree.
VolumeImage read_tiff_volume(const std::filesystem::path& path);

}  // namespace trivox
