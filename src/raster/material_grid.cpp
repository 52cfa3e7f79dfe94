#include "trivox/raster/material_grid.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <iterator>

namespace trivox {

namespace detail {

void check_raster_size(const char* what, int width_px, int height_px, int per_pixel) {
  if (width_px < 0 || height_px < 0) {
    throw Error(fmt::format("{}: size {} x {} px is negative", what, width_px, height_px));
  }
  // 2^40 values is far beyond any printer tray (a J850 tray at 600 x 300 dpi is about
  // 12e6 pixels) and keeps every index product well inside 64 bits.
  constexpr std::uint64_t kMaxValues = std::uint64_t{1} << 40;
  const std::uint64_t values = static_cast<std::uint64_t>(width_px) * static_cast<std::uint64_t>(height_px) *
                               static_cast<std::uint64_t>(per_pixel);
  if (values > kMaxValues) {
    throw Error(
        fmt::format("{}: {} x {} px with {} values per pixel is too large", what, width_px, height_px, per_pixel));
  }
}

}  // namespace detail

MaterialGrid::MaterialGrid(int width_px, int height_px, int num_materials)
    : width_px_(width_px), height_px_(height_px), num_materials_(num_materials) {
  if (num_materials < 1 || num_materials > kMaxMaterials) {
    throw Error(fmt::format("material grid: num_materials = {} is outside [1, {}]", num_materials, kMaxMaterials));
  }
  detail::check_raster_size("material grid", width_px, height_px, num_materials);
  values_.assign(static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px) *
                     static_cast<std::size_t>(num_materials),
                 0.0f);
}

namespace {

// The message for a pixel that check_fractions rejected (kept out of the hot loop).
[[noreturn]] void throw_bad_pixel(std::span<const float> f, int x, int y, float tolerance, float sum) {
  for (std::size_t k = 0; k < f.size(); ++k) {
    if (!(f[k] >= -tolerance && f[k] <= 1.0f + tolerance)) {
      throw Error(
          fmt::format("material grid: pixel ({}, {}) material {}: fraction {} is not finite and in [0, 1] "
                      "(tolerance {})",
                      x, y, k, f[k], tolerance));
    }
  }
  throw Error(fmt::format("material grid: pixel ({}, {}): fractions sum to {}, more than 1 (tolerance {})", x, y, sum,
                          tolerance));
}

}  // namespace

namespace {

// Whether every pixel of a row has its fractions in [lo, hi] and summing to at most hi, in
// two passes without branches or early exits that the compiler can vectorize: the range of
// every value (contiguous; NaN fails both comparisons), then each pixel's sum, added in the
// same order as the message's loop adds it. kM = 0: any count, m.
template <std::size_t kM>
bool row_in_range(const float* f, int width_px, std::size_t m, float lo, float hi) noexcept {
  const std::size_t n = kM > 0 ? kM : m;
  const std::size_t count = static_cast<std::size_t>(width_px) * n;
  int ok = 1;
  for (std::size_t i = 0; i < count; ++i) ok &= static_cast<int>(f[i] >= lo) & static_cast<int>(f[i] <= hi);
  for (std::size_t x = 0; x < count; x += n) {
    float sum = 0.0f;
    for (std::size_t k = 0; k < n; ++k) sum += f[x + k];
    ok &= static_cast<int>(sum <= hi);
  }
  return ok != 0;
}

}  // namespace

namespace {

void check_tolerance(float tolerance) {
  if (!std::isfinite(tolerance) || tolerance < 0.0f) {
    throw Error(fmt::format("material grid: fraction tolerance {} is not finite and >= 0", tolerance));
  }
}

}  // namespace

void MaterialGrid::check_pixel(int x, int y, float tolerance) const {
  check_tolerance(tolerance);
  const float* f = pixel(x, y).data();
  bool in_range = true;
  float sum = 0.0f;
  for (std::size_t k = 0; k < m(); ++k) {
    in_range &= f[k] >= -tolerance && f[k] <= 1.0f + tolerance;
    sum += f[k];
  }
  if (!in_range || !(sum <= 1.0f + tolerance)) throw_bad_pixel({f, m()}, x, y, tolerance, sum);
}

void MaterialGrid::check_fractions(float tolerance) const {
  check_tolerance(tolerance);
  const float lo = -tolerance;
  const float hi = 1.0f + tolerance;
  // Compiled for one to eight materials (a J850 takes 7, plus support), generic beyond.
  using RowCheck = bool (*)(const float*, int, std::size_t, float, float) noexcept;
  constexpr RowCheck kRowChecks[] = {&row_in_range<0>, &row_in_range<1>, &row_in_range<2>,
                                     &row_in_range<3>, &row_in_range<4>, &row_in_range<5>,
                                     &row_in_range<6>, &row_in_range<7>, &row_in_range<8>};
  const RowCheck row_ok = m() < std::size(kRowChecks) ? kRowChecks[m()] : &row_in_range<0>;
  for (int y = 0; y < height_px_; ++y) {
    if (row_ok(row(y).data(), width_px_, m(), lo, hi)) continue;
    // Find the first bad pixel of the row for the message.
    for (int x = 0; x < width_px_; ++x) check_pixel(x, y, tolerance);
  }
}

}  // namespace trivox
