// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// Homogeneous control points as the spline layer stores them, and their four-lane vector
// form: what the inverse layer's Bezier nets (inverse/bezier_net.cpp) share with the
// evaluation kernels (spline/volume_kernels.h). Details of the two layers' kernels
// (namespace detail), published so that the wall between them is explicit.
#pragma once

#include <array>
#include <cstring>

namespace trivox::detail {

using H = std::array<double, 4>;  // homogeneous control point (w*x, w*y, w*z, w)

// A homogeneous point as one 4-wide vector (GCC/Clang vector extension): a contraction over
// control points is then a chain of vector multiply-adds, one AVX register per partial sum.
typedef double V4 __attribute__((vector_size(32)));

// Code compiled for one SIMD target (docs/ARCHITECTURE.md, "SIMD targets") has its own copy
// of this (kernel_arithmetic-inl.h): a V4 returned across targets would not agree on
// registers. Nor on alignment: without AVX the compiler aligns V4 to 16 bytes, with AVX to
// 32, so a table of V4 that kernels of every target read is allocated 64-byte aligned, as
// the power form's is.
inline V4 load(const H& p) noexcept {
  V4 v;
  std::memcpy(&v, p.data(), sizeof v);
  return v;
}

}  // namespace trivox::detail
