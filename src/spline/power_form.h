// The polynomial pieces of a low-order volume in power form, for the per-voxel evaluators.
//
// Between consecutive distinct knots a B-spline volume is one polynomial per direction. In
// the local coordinate s = (t - t_a) / (t_b - t_a) in [0, 1] of its piece, each homogeneous
// component is sum c_ijk s^i t^j r^k; with the KU*KV*KW coefficients stored contiguously per
// piece, evaluation needs no knot-span search beyond one table look-up per direction, no
// basis recursion, and fewer multiply-adds than the de Boor contraction (for a cubic value
// plus Jacobian about 120 against 190 four-wide multiply-adds, and no divisions).
//
// The de Boor kernels (volume_kernels.h) remain the reference and the fallback: they serve
// orders above 4 and volumes whose piece table would exceed the memory cap. Tests hold the
// two to agreement within a few ulps of the coordinates' magnitude.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

#include "trivox/math.h"
#include "volume_kernels.h"  // VolumeData

namespace trivox::detail {

// The highest order per direction the power form serves.
inline constexpr int kMaxPowerOrder = 4;

// Storage on 64-byte boundaries: the kernels of the AVX targets read the table with aligned
// 32-byte loads, while code compiled without AVX (which allocates it) aligns V4 to only 16
// bytes; a piece's coefficients then also start at a cache line.
template <class T>
struct CacheLineAllocator {
  using value_type = T;
  static constexpr std::align_val_t kAlignment{64};
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlignment)); }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlignment); }
  friend bool operator==(const CacheLineAllocator&, const CacheLineAllocator&) noexcept { return true; }
};

// Pieces along one parametric direction.
struct PieceAxis {
  std::vector<double> breaks;     // piece p spans [breaks[p], breaks[p+1]); size pieces+1
  std::vector<double> inv_width;  // 1 / (breaks[p+1] - breaks[p])
  double lo = 0, hi = 0, pieces_per_unit = 0;
  int pieces = 0;

  // Piece holding t (clamped to [lo, hi]) and t's local coordinate in it. At an interior
  // breakpoint the piece to the right is chosen, and at hi the last piece: the knot-span
  // convention of KnotVector::find_span, so both evaluators agree at discontinuities.
  int locate(double t, double& s) const noexcept {
    t = t < lo ? lo : (t > hi ? hi : t);
    int p = static_cast<int>((t - lo) * pieces_per_unit);  // exact guess for uniform knots
    p = p < 0 ? 0 : (p >= pieces ? pieces - 1 : p);
    while (p > 0 && t < breaks[static_cast<std::size_t>(p)]) --p;
    while (p + 1 < pieces && t >= breaks[static_cast<std::size_t>(p) + 1]) ++p;
    s = (t - breaks[static_cast<std::size_t>(p)]) * inv_width[static_cast<std::size_t>(p)];
    return p;
  }
};

struct PowerForm {
  PieceAxis axis[3];
  int order[3] = {0, 0, 0};
  std::size_t coefficients_per_piece = 0;  // order[0] * order[1] * order[2]
  // Piece (pu, pv, pw) starts at ((pw * pieces_v + pv) * pieces_u + pu) * coefficients_per_piece;
  // within a piece, coefficient (i, j, k) of s^i t^j r^k is at i + KU * (j + KV * k).
  std::vector<V4, CacheLineAllocator<V4>> coefficients;

  const V4* piece(int pu, int pv, int pw) const noexcept {
    const auto index =
        (static_cast<std::size_t>(pw) * static_cast<std::size_t>(axis[1].pieces) + static_cast<std::size_t>(pv)) *
            static_cast<std::size_t>(axis[0].pieces) +
        static_cast<std::size_t>(pu);
    return coefficients.data() + index * coefficients_per_piece;
  }
};

// Builds the power form of the volume described by `data` when every order is 2, 3 or 4 and
// the table fits in `max_bytes`; returns false (leaving `out` empty) otherwise.
bool build_power_form(const VolumeData& data, PowerForm& out, std::size_t max_bytes);

using PowerEvaluateFn = Vec3 (*)(const PowerForm&, Vec3) noexcept;
using PowerEvaluateJacobianFn = void (*)(const PowerForm&, Vec3, Vec3&, Mat3&) noexcept;
using PowerEvaluateManyFn = void (*)(const PowerForm&, const Vec3*, Vec3*, std::size_t) noexcept;
struct PowerKernels {
  PowerEvaluateFn value;
  PowerEvaluateJacobianFn jacobian;
  PowerEvaluateManyFn many;
};
// The evaluators for these orders (each 2 to 4; nullptr otherwise) on the best SIMD target this
// processor has; they are compiled once per target in power_form_kernels.cpp.
PowerEvaluateFn select_power_evaluate(int ku, int kv, int kw) noexcept;
PowerEvaluateManyFn select_power_evaluate_many(int ku, int kv, int kw) noexcept;
PowerEvaluateJacobianFn select_power_evaluate_jacobian(int ku, int kv, int kw) noexcept;

}  // namespace trivox::detail
