// Arithmetic shared by the evaluation kernels, compiled once per SIMD target: included by the
// dispatched sources (volume_kernels.cpp, power_form_kernels.cpp) inside their per-target
// namespace, after hwy/foreach_target.h has set HWY_TARGET (docs/ARCHITECTURE.md, "SIMD
// targets"). No include guard of the usual kind: it must be compiled anew for each target.
//
// Rounding. The project compiles with -ffp-contract=off, so the compiler fuses nothing by
// itself; the kernels fuse where they say so, here. On targets with a fused multiply-add
// instruction (AVX2, AVX-512) every multiply_add rounds once, so those targets give the same
// numbers bit for bit; on targets without one (SSE4, the portable fallback) it is a multiply
// and an add, two roundings: numbers within a few ulps of the fused ones
// (docs/PERFORMANCE.md, "SIMD targets", bounds the difference in the slices).
#if defined(TRIVOX_KERNEL_ARITHMETIC_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRIVOX_KERNEL_ARITHMETIC_INL_H_
#undef TRIVOX_KERNEL_ARITHMETIC_INL_H_
#else
#define TRIVOX_KERNEL_ARITHMETIC_INL_H_
#endif

#if HWY_ARCH_X86 && (HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL)
#define TRIVOX_KERNEL_FUSED 1
#else
#define TRIVOX_KERNEL_FUSED 0
#endif

// c + a * b, one rounding where the target fuses.
inline double fused_multiply_add(double a, double b, double c) noexcept {
#if TRIVOX_KERNEL_FUSED
  return std::fma(a, b, c);  // one instruction on these targets
#else
  return a * b + c;
#endif
}

// c + a * b in each of the four lanes.
inline V4 multiply_add(double a, const V4& b, const V4& c) noexcept {
#if TRIVOX_KERNEL_FUSED
  return _mm256_fmadd_pd(_mm256_set1_pd(a), b, c);  // __m256d is V4's type
#else
  return a * b + c;
#endif
}

#undef TRIVOX_KERNEL_FUSED

// A control point as a V4. This target's own copy of spline/detail/homogeneous.h's load: a
// function returning a V4 is not called across targets (their conventions for it differ).
inline V4 load_point(const H& p) noexcept {
  V4 v;
  std::memcpy(&v, p.data(), sizeof v);
  return v;
}

// The Euclidean value and Jacobian from the homogeneous value S and its partials, each
// partial first scaled by `scale` (the chain rule of a local coordinate): the quotient rule
// x = A / W, dx = (dA - x dW) / W.
inline void homogeneous_to_euclidean(const V4& S, const V4& Su, const V4& Sv, const V4& Sw,
                                     const std::array<double, 3>& scale, Vec3& value, Mat3& jac) noexcept {
  const double inv = 1.0 / S[3];
  value = {S[0] * inv, S[1] * inv, S[2] * inv};
  const V4* partial[3] = {&Su, &Sv, &Sw};
  for (std::size_t col = 0; col < 3; ++col) {
    const V4& p = *partial[col];
    const double k = scale[col] * inv;
    jac.m[0][col] = fused_multiply_add(-value.x, p[3], p[0]) * k;
    jac.m[1][col] = fused_multiply_add(-value.y, p[3], p[1]) * k;
    jac.m[2][col] = fused_multiply_add(-value.z, p[3], p[2]) * k;
  }
}

#endif  // include toggle
