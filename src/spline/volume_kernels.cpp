// The de Boor kernels' tables, one per SIMD target: this file is compiled once for each
// target Highway's foreach_target.h enables (it includes itself through HWY_TARGET_INCLUDE),
// and select_* hand out the table of the best target the processor supports.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "spline/volume_kernels.cpp"
#include <hwy/foreach_target.h>  // must precede highway.h
#include <hwy/highway.h>

#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "trivox/spline/detail/basis.h"
#include "volume_kernels.h"

#if HWY_ARCH_X86
#include <immintrin.h>  // the fused multiply-add of the AVX2 and AVX-512 targets
#endif

HWY_BEFORE_NAMESPACE();
namespace trivox::detail {
namespace HWY_NAMESPACE {

#include "kernel_arithmetic-inl.h"
#include "volume_kernels-inl.h"

constexpr int kFirstFixed = 2, kLastFixed = 4;
constexpr int kFixedCount = kLastFixed - kFirstFixed + 1;

template <int KU, int KV, int KW>
constexpr std::pair<EvaluateFn, EvaluateJacobianFn> kernels() {
  return {&evaluate_kernel<KU, KV, KW>, &evaluate_jacobian_kernel<KU, KV, KW>};
}

// Table of specialised kernels indexed by (ku - 2) + 3 (kv - 2) + 9 (kw - 2).
template <std::size_t... I>
constexpr auto make_table(std::index_sequence<I...>) {
  return std::array<std::pair<EvaluateFn, EvaluateJacobianFn>, sizeof...(I)>{
      kernels<kFirstFixed + static_cast<int>(I % kFixedCount),
              kFirstFixed + static_cast<int>((I / kFixedCount) % kFixedCount),
              kFirstFixed + static_cast<int>(I / (kFixedCount * kFixedCount))>()...};
}

constexpr auto kTable = make_table(std::make_index_sequence<kFixedCount * kFixedCount * kFixedCount>{});

// The kernels of this target for these orders.
std::pair<EvaluateFn, EvaluateJacobianFn> de_boor_kernels(int ku, int kv, int kw) {
  auto fixed = [](int k) { return k >= kFirstFixed && k <= kLastFixed; };
  if (!fixed(ku) || !fixed(kv) || !fixed(kw)) return kernels<0, 0, 0>();
  return kTable[static_cast<std::size_t>((ku - kFirstFixed) + kFixedCount * (kv - kFirstFixed) +
                                         kFixedCount * kFixedCount * (kw - kFirstFixed))];
}

}  // namespace HWY_NAMESPACE
}  // namespace trivox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace trivox::detail {

HWY_EXPORT(de_boor_kernels);

EvaluateFn select_evaluate(int ku, int kv, int kw) noexcept {
  return HWY_DYNAMIC_DISPATCH(de_boor_kernels)(ku, kv, kw).first;
}

EvaluateJacobianFn select_evaluate_jacobian(int ku, int kv, int kw) noexcept {
  return HWY_DYNAMIC_DISPATCH(de_boor_kernels)(ku, kv, kw).second;
}

}  // namespace trivox::detail
#endif  // HWY_ONCE
