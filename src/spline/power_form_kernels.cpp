// The power form's evaluators, compiled once per SIMD target: this file includes itself
// through HWY_TARGET_INCLUDE for every target Highway's foreach_target.h enables, and the
// select_power_* functions hand out the best target's evaluators (docs/ARCHITECTURE.md,
// "SIMD targets").
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "spline/power_form_kernels.cpp"
#include <hwy/foreach_target.h>  // must precede highway.h
#include <hwy/highway.h>

#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "power_form.h"

#if HWY_ARCH_X86
#include <immintrin.h>  // the fused multiply-add of the AVX2 and AVX-512 targets
#endif

HWY_BEFORE_NAMESPACE();
namespace trivox::detail {
namespace HWY_NAMESPACE {

#include "kernel_arithmetic-inl.h"

// Powers 1, s, s^2, ... and their derivatives 0, 1, 2s, 3s^2, ... for a compile-time order.
template <int K>
struct Powers {
  double p[K], d[K];
  explicit Powers(double s) noexcept {
    p[0] = 1.0;
    d[0] = 0.0;
    for (int i = 1; i < K; ++i) {
      p[i] = p[i - 1] * s;
      d[i] = i * p[i - 1];
    }
  }
};

// The piece holding (u, v, w), the local coordinates in it and the scale of d/d(local) to
// d/d(parameter) per direction.
struct PieceAt {
  const V4* coefficients;
  double local[3];
  std::array<double, 3> inv_width;
  PieceAt(const PowerForm& f, Vec3 uvw) noexcept {
    int p[3];
    for (int d = 0; d < 3; ++d) {
      p[d] = f.axis[d].locate(uvw[d], local[d]);
      inv_width[static_cast<std::size_t>(d)] = f.axis[d].inv_width[static_cast<std::size_t>(p[d])];
    }
    coefficients = f.piece(p[0], p[1], p[2]);
  }
};

// Values at N parameters, the N evaluations interleaved loop by loop: they are
// independent, so their latencies overlap where one evaluation alone would wait on each
// multiply-add. Every point goes through exactly the same operations as with N = 1 (the
// single-point evaluator is this function's N = 1 instance, and every multiply-add is
// written out: the project compiles with -ffp-contract=off), so the results are identical.
template <int KU, int KV, int KW, int N>
void power_evaluate_n(const PowerForm& f, const Vec3* uvw, Vec3* out) noexcept {
  const V4* c[N];
  double ps[N][KU], pt[N][KV], pr[N][KW];
  for (int n = 0; n < N; ++n) {
    const PieceAt at(f, uvw[n]);
    c[n] = at.coefficients;
    const Powers<KU> s(at.local[0]);
    const Powers<KV> t(at.local[1]);
    const Powers<KW> r(at.local[2]);
    for (int i = 0; i < KU; ++i) ps[n][i] = s.p[i];
    for (int j = 0; j < KV; ++j) pt[n][j] = t.p[j];
    for (int k = 0; k < KW; ++k) pr[n][k] = r.p[k];
  }
  V4 acc[N];
  for (int n = 0; n < N; ++n) acc[n] = V4{};
  for (int k = 0; k < KW; ++k) {
    V4 plane[N];
    for (int n = 0; n < N; ++n) plane[n] = V4{};
    for (int j = 0; j < KV; ++j)
      for (int n = 0; n < N; ++n) {
        const V4* row = c[n] + KU * (j + KV * k);
        V4 line = row[0];
        for (int i = 1; i < KU; ++i) line = multiply_add(ps[n][i], row[i], line);
        plane[n] = multiply_add(pt[n][j], line, plane[n]);
      }
    for (int n = 0; n < N; ++n) acc[n] = multiply_add(pr[n][k], plane[n], acc[n]);
  }
  for (int n = 0; n < N; ++n) {
    const double inv = 1.0 / acc[n][3];
    out[n] = {acc[n][0] * inv, acc[n][1] * inv, acc[n][2] * inv};
  }
}

template <int KU, int KV, int KW>
Vec3 power_evaluate(const PowerForm& f, Vec3 uvw) noexcept {
  Vec3 out;
  power_evaluate_n<KU, KV, KW, 1>(f, &uvw, &out);
  return out;
}

// Groups of four, then the rest one by one.
template <int KU, int KV, int KW>
void power_evaluate_many(const PowerForm& f, const Vec3* uvw, Vec3* out, std::size_t count) noexcept {
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) power_evaluate_n<KU, KV, KW, 4>(f, uvw + i, out + i);
  for (; i < count; ++i) power_evaluate_n<KU, KV, KW, 1>(f, uvw + i, out + i);
}

template <int KU, int KV, int KW>
void power_evaluate_jacobian(const PowerForm& f, Vec3 uvw, Vec3& value, Mat3& jac) noexcept {
  const PieceAt at(f, uvw);
  const V4* c = at.coefficients;
  const Powers<KU> ps(at.local[0]);
  const Powers<KV> pt(at.local[1]);
  const Powers<KW> pr(at.local[2]);
  V4 S{}, Su{}, Sv{}, Sw{};
  for (int k = 0; k < KW; ++k) {
    V4 P{}, Pu{}, Pv{};
    for (int j = 0; j < KV; ++j) {
      const V4* row = c + KU * (j + KV * k);
      V4 L = row[0], Lu = row[1];
      for (int i = 1; i < KU; ++i) L = multiply_add(ps.p[i], row[i], L);
      for (int i = 2; i < KU; ++i) Lu = multiply_add(ps.d[i], row[i], Lu);
      P = multiply_add(pt.p[j], L, P);
      Pu = multiply_add(pt.p[j], Lu, Pu);
      Pv = multiply_add(pt.d[j], L, Pv);
    }
    S = multiply_add(pr.p[k], P, S);
    Su = multiply_add(pr.p[k], Pu, Su);
    Sv = multiply_add(pr.p[k], Pv, Sv);
    Sw = multiply_add(pr.d[k], P, Sw);
  }
  // Back from local coordinates to parameters (chain rule), then the quotient rule.
  homogeneous_to_euclidean(S, Su, Sv, Sw, at.inv_width, value, jac);
}

constexpr int kFirst = 2, kCount = kMaxPowerOrder - kFirst + 1;

template <std::size_t I>
constexpr PowerKernels kernels_for() {
  constexpr int ku = kFirst + static_cast<int>(I % kCount);
  constexpr int kv = kFirst + static_cast<int>((I / kCount) % kCount);
  constexpr int kw = kFirst + static_cast<int>(I / (kCount * kCount));
  return {&power_evaluate<ku, kv, kw>, &power_evaluate_jacobian<ku, kv, kw>, &power_evaluate_many<ku, kv, kw>};
}

template <std::size_t... I>
constexpr auto make_table(std::index_sequence<I...>) {
  return std::array<PowerKernels, sizeof...(I)>{kernels_for<I>()...};
}

constexpr auto kTable = make_table(std::make_index_sequence<kCount * kCount * kCount>{});

// This target's evaluators for orders (ku, kv, kw), each in 2..4 (checked by the caller).
PowerKernels power_kernels(int ku, int kv, int kw) {
  return kTable[static_cast<std::size_t>((ku - kFirst) + kCount * (kv - kFirst) + kCount * kCount * (kw - kFirst))];
}

}  // namespace HWY_NAMESPACE
}  // namespace trivox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace trivox::detail {

HWY_EXPORT(power_kernels);

namespace {
bool supported(int k) noexcept { return k >= 2 && k <= kMaxPowerOrder; }
bool supported(int ku, int kv, int kw) noexcept { return supported(ku) && supported(kv) && supported(kw); }
}  // namespace

PowerEvaluateFn select_power_evaluate(int ku, int kv, int kw) noexcept {
  return supported(ku, kv, kw) ? HWY_DYNAMIC_DISPATCH(power_kernels)(ku, kv, kw).value : nullptr;
}

PowerEvaluateJacobianFn select_power_evaluate_jacobian(int ku, int kv, int kw) noexcept {
  return supported(ku, kv, kw) ? HWY_DYNAMIC_DISPATCH(power_kernels)(ku, kv, kw).jacobian : nullptr;
}

PowerEvaluateManyFn select_power_evaluate_many(int ku, int kv, int kw) noexcept {
  return supported(ku, kv, kw) ? HWY_DYNAMIC_DISPATCH(power_kernels)(ku, kv, kw).many : nullptr;
}

}  // namespace trivox::detail
#endif  // HWY_ONCE
