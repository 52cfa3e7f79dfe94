#include "power_form.h"

#include <array>
#include <bit>
#include <cmath>
#include <utility>

#include "trivox/spline/detail/basis.h"

#if defined(__FMA__) && defined(__AVX__)
#include <immintrin.h>
#endif

namespace trivox::detail {

namespace {

constexpr int kMaxPowerOrder = 4;

// Along one direction: the pieces of the domain and, per piece, the matrix taking the k
// local B-spline coefficients to the k power coefficients in the local coordinate s.
// M[i][a] = N_a^(i)(t_start) * width^i / i! (Taylor expansion at the piece's start).
struct AxisPieces {
  PieceAxis axis;
  std::vector<int> first_basis;  // index of the first non-zero basis function per piece
  std::vector<std::array<std::array<double, kMaxPowerOrder>, kMaxPowerOrder>> matrix;
};

AxisPieces split_axis(const KnotVector& kv) {
  AxisPieces out;
  const int k = kv.order();
  const auto U = kv.knots();
  const double lo = kv.lo(), hi = kv.hi();
  // Span s covers [U[s], U[s+1]); the domain's spans are s = k-1 .. num_basis-1.
  for (int s = k - 1; s < kv.num_basis(); ++s) {
    const double a = U[static_cast<std::size_t>(s)], b = U[static_cast<std::size_t>(s) + 1];
    if (!(a < b)) continue;
    out.axis.breaks.push_back(a);
    out.axis.inv_width.push_back(1.0 / (b - a));
    out.first_basis.push_back(s - (k - 1));
    double ders[kMaxPowerOrder * kMaxPowerOrder] = {};
    basis_derivatives(kv, s, a, k - 1, ders);
    auto& m = out.matrix.emplace_back();
    double scale = 1.0;  // width^i / i!
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) m[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = ders[i * k + j] * scale;
      scale *= (b - a) / (i + 1);
    }
  }
  out.axis.breaks.push_back(hi);
  out.axis.pieces = static_cast<int>(out.axis.inv_width.size());
  out.axis.lo = lo;
  out.axis.hi = hi;
  out.axis.pieces_per_unit = out.axis.pieces / (hi - lo);
  return out;
}

}  // namespace

bool build_power_form(const VolumeData& data, PowerForm& out, std::size_t max_bytes) {
  out = PowerForm{};
  int k[3];
  for (int d = 0; d < 3; ++d) {
    k[d] = data.knots[d]->order();
    if (k[d] < 2 || k[d] > kMaxPowerOrder) return false;
  }
  // Count pieces before building anything, so an oversized volume costs nothing.
  std::size_t pieces = 1;
  for (int d = 0; d < 3; ++d) {
    const auto U = data.knots[d]->knots();
    std::size_t n = 0;
    for (int s = k[d] - 1; s < data.knots[d]->num_basis(); ++s)
      if (U[static_cast<std::size_t>(s)] < U[static_cast<std::size_t>(s) + 1]) ++n;
    pieces *= n;
  }
  const std::size_t per_piece = static_cast<std::size_t>(k[0] * k[1] * k[2]);
  if (pieces * per_piece * sizeof(V4) > max_bytes) return false;

  AxisPieces ax[3] = {split_axis(*data.knots[0]), split_axis(*data.knots[1]), split_axis(*data.knots[2])};
  for (int d = 0; d < 3; ++d) {
    out.axis[d] = ax[d].axis;
    out.order[d] = k[d];
  }
  out.coefficients_per_piece = per_piece;
  out.coefficients.resize(pieces * per_piece);

  // Per piece: C = (Mu x Mv x Mw) P, applied one direction at a time.
  std::vector<V4> tmp1(per_piece), tmp2(per_piece);
  const int ku = k[0], kv = k[1], kw = k[2];
  auto at = [&](int a, int b, int c) { return static_cast<std::size_t>(a + ku * (b + kv * c)); };
  for (int pw = 0; pw < ax[2].axis.pieces; ++pw)
    for (int pv = 0; pv < ax[1].axis.pieces; ++pv)
      for (int pu = 0; pu < ax[0].axis.pieces; ++pu) {
        const auto& Mu = ax[0].matrix[static_cast<std::size_t>(pu)];
        const auto& Mv = ax[1].matrix[static_cast<std::size_t>(pv)];
        const auto& Mw = ax[2].matrix[static_cast<std::size_t>(pw)];
        const int fu = ax[0].first_basis[static_cast<std::size_t>(pu)];
        const int fv = ax[1].first_basis[static_cast<std::size_t>(pv)];
        const int fw = ax[2].first_basis[static_cast<std::size_t>(pw)];
        for (int c = 0; c < kw; ++c)
          for (int b = 0; b < kv; ++b) {
            const H* row = data.points + static_cast<std::size_t>(fw + c) * data.stride_w +
                           static_cast<std::size_t>(fv + b) * data.stride_v + static_cast<std::size_t>(fu);
            for (int i = 0; i < ku; ++i) {
              V4 sum{};
              for (int a = 0; a < ku; ++a)
                sum += Mu[static_cast<std::size_t>(i)][static_cast<std::size_t>(a)] * load(row[a]);
              tmp1[at(i, b, c)] = sum;
            }
          }
        for (int c = 0; c < kw; ++c)
          for (int j = 0; j < kv; ++j)
            for (int i = 0; i < ku; ++i) {
              V4 sum{};
              for (int b = 0; b < kv; ++b)
                sum += Mv[static_cast<std::size_t>(j)][static_cast<std::size_t>(b)] * tmp1[at(i, b, c)];
              tmp2[at(i, j, c)] = sum;
            }
        V4* dst =
            out.coefficients.data() + ((static_cast<std::size_t>(pw) * static_cast<std::size_t>(ax[1].axis.pieces) +
                                        static_cast<std::size_t>(pv)) *
                                           static_cast<std::size_t>(ax[0].axis.pieces) +
                                       static_cast<std::size_t>(pu)) *
                                          per_piece;
        for (int l = 0; l < kw; ++l)
          for (int j = 0; j < kv; ++j)
            for (int i = 0; i < ku; ++i) {
              V4 sum{};
              for (int c = 0; c < kw; ++c)
                sum += Mw[static_cast<std::size_t>(l)][static_cast<std::size_t>(c)] * tmp2[at(i, j, c)];
              dst[at(i, j, l)] = sum;
            }
      }
  return true;
}

namespace {

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

// c + a * b, four lanes, fused (one rounding) where the machine has fused multiply-add and
// plain otherwise, but in either case written out: the compiler may fuse a written `c + a * b`
// in one instance of a template and not in another (it did, in the sanitizers' build for
// Zen 4), and the interleaved evaluators below must give the single-point evaluator's numbers
// bit for bit.
inline V4 multiply_add(double a, const V4& b, const V4& c) noexcept {
#if defined(__FMA__) && defined(__AVX__)
  return std::bit_cast<V4>(_mm256_fmadd_pd(_mm256_set1_pd(a), std::bit_cast<__m256d>(b), std::bit_cast<__m256d>(c)));
#elif defined(__FP_FAST_FMA)
  return V4{std::fma(a, b[0], c[0]), std::fma(a, b[1], c[1]), std::fma(a, b[2], c[2]), std::fma(a, b[3], c[3])};
#else
  return a * b + c;  // no fused instruction to contract into
#endif
}

// Values at N parameters, the N evaluations interleaved loop by loop: they are
// independent, so their latencies overlap where one evaluation alone would wait on each
// multiply-add. Every point goes through exactly the same operations as with N = 1 (the
// single-point evaluator is this function's N = 1 instance, and every multiply-add is
// written out), so the results are identical.
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
      for (int i = 1; i < KU; ++i) L += ps.p[i] * row[i];
      for (int i = 2; i < KU; ++i) Lu += ps.d[i] * row[i];
      P += pt.p[j] * L;
      Pu += pt.p[j] * Lu;
      Pv += pt.d[j] * L;
    }
    S += pr.p[k] * P;
    Su += pr.p[k] * Pu;
    Sv += pr.p[k] * Pv;
    Sw += pr.d[k] * P;
  }
  // Back from local coordinates to parameters (chain rule), then the quotient rule.
  homogeneous_to_euclidean(S, Su, Sv, Sw, at.inv_width, value, jac);
}

constexpr int kFirst = 2, kCount = kMaxPowerOrder - kFirst + 1;

struct Kernels {
  PowerEvaluateFn value;
  PowerEvaluateJacobianFn jacobian;
  PowerEvaluateManyFn many;
};

template <std::size_t I>
constexpr Kernels kernels_for() {
  constexpr int ku = kFirst + static_cast<int>(I % kCount);
  constexpr int kv = kFirst + static_cast<int>((I / kCount) % kCount);
  constexpr int kw = kFirst + static_cast<int>(I / (kCount * kCount));
  return {&power_evaluate<ku, kv, kw>, &power_evaluate_jacobian<ku, kv, kw>, &power_evaluate_many<ku, kv, kw>};
}

template <std::size_t... I>
constexpr auto make_table(std::index_sequence<I...>) {
  return std::array<Kernels, sizeof...(I)>{kernels_for<I>()...};
}

constexpr auto kTable = make_table(std::make_index_sequence<kCount * kCount * kCount>{});

std::size_t slot(int ku, int kv, int kw) noexcept {
  return static_cast<std::size_t>((ku - kFirst) + kCount * (kv - kFirst) + kCount * kCount * (kw - kFirst));
}
bool supported(int k) noexcept { return k >= kFirst && k <= kMaxPowerOrder; }

}  // namespace

PowerEvaluateFn select_power_evaluate(int ku, int kv, int kw) noexcept {
  if (!supported(ku) || !supported(kv) || !supported(kw)) return nullptr;
  return kTable[slot(ku, kv, kw)].value;
}

PowerEvaluateJacobianFn select_power_evaluate_jacobian(int ku, int kv, int kw) noexcept {
  if (!supported(ku) || !supported(kv) || !supported(kw)) return nullptr;
  return kTable[slot(ku, kv, kw)].jacobian;
}

PowerEvaluateManyFn select_power_evaluate_many(int ku, int kv, int kw) noexcept {
  if (!supported(ku) || !supported(kv) || !supported(kw)) return nullptr;
  return kTable[slot(ku, kv, kw)].many;
}

}  // namespace trivox::detail
