#include "power_form.h"

#include <array>
#include <vector>

#include "trivox/spline/detail/basis.h"

namespace trivox::detail {

namespace {

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

}  // namespace trivox::detail
