#include "volume_kernels.h"

#include <utility>

namespace trivox::detail {

namespace {

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

bool fixed(int k) { return k >= kFirstFixed && k <= kLastFixed; }
std::size_t slot(int ku, int kv, int kw) {
  return static_cast<std::size_t>((ku - kFirstFixed) + kFixedCount * (kv - kFirstFixed) +
                                  kFixedCount * kFixedCount * (kw - kFirstFixed));
}

}  // namespace

EvaluateFn select_evaluate(int ku, int kv, int kw) noexcept {
  if (fixed(ku) && fixed(kv) && fixed(kw)) return kTable[slot(ku, kv, kw)].first;
  return &evaluate_kernel<0, 0, 0>;
}

EvaluateJacobianFn select_evaluate_jacobian(int ku, int kv, int kw) noexcept {
  if (fixed(ku) && fixed(kv) && fixed(kw)) return kTable[slot(ku, kv, kw)].second;
  return &evaluate_jacobian_kernel<0, 0, 0>;
}

}  // namespace trivox::detail
