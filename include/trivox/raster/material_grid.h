// Rasters of one slice: per-pixel material fractions (the dithering input), the part's
// inside mask, and the label image (the dithering output).
//
// Frame: pixel (x, y) with x along the printer's fast, 600 dpi axis and y along the 300 dpi
// axis; x in [0, width_px), y in [0, height_px). Storage is row-major: rows of constant y,
// x fastest, row 0 first (the top row of the PNG written for the slice). Pixel centres and
// physical pitches belong to the slicer and the printer profile, not to these types.
#pragma once

#include "trivox/limits.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "trivox/error.h"

namespace trivox {

namespace detail {
// Throws Error unless 0 <= width_px, height_px and the pixel count times `per_pixel` values
// stays far from overflowing a size_t (2^40 values at most).
void check_raster_size(const char* what, int width_px, int height_px, int per_pixel);
}  // namespace detail

// One value of type T per pixel, row-major as described above.
template <class T>
class PixelPlane {
 public:
  PixelPlane() = default;
  // Every pixel holds `fill`. Throws Error when a size is negative or absurdly large.
  PixelPlane(int width_px, int height_px, T fill = T{}) : width_px_(width_px), height_px_(height_px) {
    detail::check_raster_size("pixel plane", width_px, height_px, 1);
    values_.assign(static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px), fill);
  }

  int width_px() const noexcept { return width_px_; }
  int height_px() const noexcept { return height_px_; }

  // Unchecked access; (x, y) must lie inside the plane.
  T& at(int x, int y) noexcept { return values_[index(x, y)]; }
  T at(int x, int y) const noexcept { return values_[index(x, y)]; }
  std::span<T> row(int y) noexcept { return {values_.data() + index(0, y), static_cast<std::size_t>(width_px_)}; }
  std::span<const T> row(int y) const noexcept {
    return {values_.data() + index(0, y), static_cast<std::size_t>(width_px_)};
  }
  std::span<T> values() noexcept { return values_; }
  std::span<const T> values() const noexcept { return values_; }

  void fill(T value) { values_.assign(values_.size(), value); }

  bool operator==(const PixelPlane&) const = default;

 private:
  std::size_t index(int x, int y) const noexcept {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_px_) + static_cast<std::size_t>(x);
  }

  int width_px_ = 0;
  int height_px_ = 0;
  std::vector<T> values_;
};

// Which pixels belong to the part: nonzero = inside. Pixels outside are background; the
// dithering neither writes material there nor lets diffused error flow through them.
class InsideMask : public PixelPlane<std::uint8_t> {
 public:
  using PixelPlane::PixelPlane;
  bool inside(int x, int y) const noexcept { return at(x, y) != 0; }
};

// The dithering output: 0 = void (background, or an inside pixel left empty), and
// 1..m = material index + 1.
class LabelImage : public PixelPlane<std::uint8_t> {
 public:
  using PixelPlane::PixelPlane;
  static constexpr std::uint8_t kVoid = 0;
  static constexpr std::uint8_t label_of_material(int material) noexcept {
    return static_cast<std::uint8_t>(material + 1);
  }
};

// Per-pixel volume fractions of `num_materials` materials. Each fraction lies in [0, 1] and
// a pixel's fractions sum to at most 1; the remainder, 1 - sum, is void. A new grid is all
// void (every fraction 0).
class MaterialGrid {
 public:
  MaterialGrid() = default;
  // Throws Error when a size is negative or too large, or num_materials is outside
  // [1, kMaxMaterials].
  MaterialGrid(int width_px, int height_px, int num_materials);

  int width_px() const noexcept { return width_px_; }
  int height_px() const noexcept { return height_px_; }
  int num_materials() const noexcept { return num_materials_; }

  // The num_materials fractions of pixel (x, y), which must lie inside the grid.
  std::span<float> pixel(int x, int y) noexcept { return {values_.data() + offset(x, y), m()}; }
  std::span<const float> pixel(int x, int y) const noexcept { return {values_.data() + offset(x, y), m()}; }
  float& at(int x, int y, int material) noexcept { return values_[offset(x, y) + static_cast<std::size_t>(material)]; }
  float at(int x, int y, int material) const noexcept {
    return values_[offset(x, y) + static_cast<std::size_t>(material)];
  }
  // Row y: width_px * num_materials floats, pixel after pixel.
  std::span<float> row(int y) noexcept {
    return {values_.data() + offset(0, y), static_cast<std::size_t>(width_px_) * m()};
  }
  std::span<const float> row(int y) const noexcept {
    return {values_.data() + offset(0, y), static_cast<std::size_t>(width_px_) * m()};
  }
  std::span<const float> values() const noexcept { return values_; }

  // Throws Error naming the first offending pixel (in storage order) and the rule it breaks
  // when a fraction is not finite or lies outside [-tolerance, 1 + tolerance], or a pixel's
  // fractions sum to more than 1 + tolerance. `tolerance` absorbs the rounding of fractions
  // computed in floating point; it must be finite and >= 0.
  void check_fractions(float tolerance) const;
  // The same rule for pixel (x, y) alone, for a caller that checks pixels as it writes them.
  void check_pixel(int x, int y, float tolerance) const;

  bool operator==(const MaterialGrid&) const = default;

 private:
  std::size_t m() const noexcept { return static_cast<std::size_t>(num_materials_); }
  std::size_t offset(int x, int y) const noexcept {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_px_) + static_cast<std::size_t>(x)) * m();
  }

  int width_px_ = 0;
  int height_px_ = 0;
  int num_materials_ = 1;
  std::vector<float> values_;
};

}  // namespace trivox
