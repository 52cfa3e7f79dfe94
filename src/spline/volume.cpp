#include "trivox/spline/volume.h"

#include <algorithm>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/spline/basis.h"

namespace trivox {

namespace {
using H = std::array<double, 4>;  // homogeneous point (w*x, w*y, w*z, w)

inline void axpy(H& acc, double s, const H& p) noexcept {
  for (int c = 0; c < 4; ++c) acc[static_cast<std::size_t>(c)] += s * p[static_cast<std::size_t>(c)];
}
}  // namespace

Volume::Volume(TensorSpline spline) : spline_(std::move(spline)) {
  if (spline_.param_dim() != 3 || spline_.point_dim() != 3)
    throw ModelError(fmt::format("a volume needs 3 parametric directions and 3D points, got {} and {}",
                                 spline_.param_dim(), spline_.point_dim()));
  for (int d = 0; d < 3; ++d) num_basis_[static_cast<std::size_t>(d)] = spline_.knots(d).num_basis();
  domain_ = ParamBox{{spline_.lo(0), spline_.lo(1), spline_.lo(2)}, {spline_.hi(0), spline_.hi(1), spline_.hi(2)}};
  hpoints_.resize(static_cast<std::size_t>(num_basis_[0] * num_basis_[1] * num_basis_[2]));
  std::size_t n = 0;
  for (int k = 0; k < num_basis_[2]; ++k)
    for (int j = 0; j < num_basis_[1]; ++j)
      for (int i = 0; i < num_basis_[0]; ++i) {
        const int ci = spline_.knots(0).ctrl_index(i), cj = spline_.knots(1).ctrl_index(j),
                  ck = spline_.knots(2).ctrl_index(k);
        const auto p = spline_.point(ci, cj, ck);
        const double w = spline_.weight(ci, cj, ck);
        hpoints_[n++] = {w * p[0], w * p[1], w * p[2], w};
      }
  bounds_ = spline_.control_box();
}

Vec3 Volume::evaluate(Vec3 uvw) const noexcept {
  std::array<std::array<double, kMaxOrder>, 3> N;
  std::array<int, 3> first{}, order{};
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline_.knots(d);
    const double t = std::clamp(uvw[d], kv.lo(), kv.hi());
    const int span = kv.find_span(t);
    basis_functions(kv, span, t, N[static_cast<std::size_t>(d)].data());
    first[static_cast<std::size_t>(d)] = span - kv.degree();
    order[static_cast<std::size_t>(d)] = kv.order();
  }
  const auto nu = static_cast<std::size_t>(num_basis_[0]);
  const auto nuv = nu * static_cast<std::size_t>(num_basis_[1]);
  H acc{};
  for (int c = 0; c < order[2]; ++c) {
    H plane{};
    for (int b = 0; b < order[1]; ++b) {
      const H* row = &hpoints_[static_cast<std::size_t>(first[2] + c) * nuv +
                               static_cast<std::size_t>(first[1] + b) * nu + static_cast<std::size_t>(first[0])];
      H line{};
      for (int a = 0; a < order[0]; ++a) axpy(line, N[0][static_cast<std::size_t>(a)], row[a]);
      axpy(plane, N[1][static_cast<std::size_t>(b)], line);
    }
    axpy(acc, N[2][static_cast<std::size_t>(c)], plane);
  }
  const double inv = 1.0 / acc[3];
  return {acc[0] * inv, acc[1] * inv, acc[2] * inv};
}

void Volume::evaluate_jacobian(Vec3 uvw, Vec3& value, Mat3& jacobian) const noexcept {
  // Basis values and first derivatives per direction: D[d][0..k) values, D[d][k..2k) derivatives.
  std::array<std::array<double, 2 * kMaxOrder>, 3> D;
  std::array<int, 3> first{}, order{};
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline_.knots(d);
    const double t = std::clamp(uvw[d], kv.lo(), kv.hi());
    const int span = kv.find_span(t);
    basis_derivatives(kv, span, t, 1, D[static_cast<std::size_t>(d)].data());
    first[static_cast<std::size_t>(d)] = span - kv.degree();
    order[static_cast<std::size_t>(d)] = kv.order();
  }
  const int ku = order[0], kv_ = order[1], kw = order[2];
  const double* Nu = D[0].data();
  const double* dNu = D[0].data() + ku;
  const double* Nv = D[1].data();
  const double* dNv = D[1].data() + kv_;
  const double* Nw = D[2].data();
  const double* dNw = D[2].data() + kw;
  const auto nu = static_cast<std::size_t>(num_basis_[0]);
  const auto nuv = nu * static_cast<std::size_t>(num_basis_[1]);

  // Tensor contraction u, then v, then w; S = value, Su/Sv/Sw = partial derivatives of the
  // homogeneous point.
  H S{}, Su{}, Sv{}, Sw{};
  for (int c = 0; c < kw; ++c) {
    H P{}, Pu{}, Pv{};
    for (int b = 0; b < kv_; ++b) {
      const H* row = &hpoints_[static_cast<std::size_t>(first[2] + c) * nuv +
                               static_cast<std::size_t>(first[1] + b) * nu + static_cast<std::size_t>(first[0])];
      H L{}, Lu{};
      for (int a = 0; a < ku; ++a) {
        axpy(L, Nu[a], row[a]);
        axpy(Lu, dNu[a], row[a]);
      }
      axpy(P, Nv[b], L);
      axpy(Pu, Nv[b], Lu);
      axpy(Pv, dNv[b], L);
    }
    axpy(S, Nw[c], P);
    axpy(Su, Nw[c], Pu);
    axpy(Sv, Nw[c], Pv);
    axpy(Sw, dNw[c], P);
  }
  // Quotient rule on the homogeneous coordinates: x = A/W, dx = (dA - x dW)/W.
  const double inv = 1.0 / S[3];
  value = {S[0] * inv, S[1] * inv, S[2] * inv};
  const H* partial[3] = {&Su, &Sv, &Sw};
  for (int col = 0; col < 3; ++col) {
    const H& d = *partial[col];
    for (int r = 0; r < 3; ++r)
      jacobian.m[static_cast<std::size_t>(r)][static_cast<std::size_t>(col)] =
          (d[static_cast<std::size_t>(r)] - value[r] * d[3]) * inv;
  }
}

Box3 Volume::bounds(const ParamBox& box) const noexcept {
  // Basis functions whose support [t_i, t_{i+k}) meets [lo, hi] along each direction.
  std::array<int, 3> i0{}, i1{};
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline_.knots(d);
    const double lo = std::clamp(box.lo[d], kv.lo(), kv.hi());
    const double hi = std::clamp(box.hi[d], kv.lo(), kv.hi());
    i0[static_cast<std::size_t>(d)] = kv.find_span(lo) - kv.degree();
    i1[static_cast<std::size_t>(d)] = kv.find_span(hi);
  }
  Box3 out;
  const auto nu = static_cast<std::size_t>(num_basis_[0]);
  const auto nuv = nu * static_cast<std::size_t>(num_basis_[1]);
  for (int k = i0[2]; k <= i1[2]; ++k)
    for (int j = i0[1]; j <= i1[1]; ++j)
      for (int i = i0[0]; i <= i1[0]; ++i) {
        const H& h = hpoints_[static_cast<std::size_t>(k) * nuv + static_cast<std::size_t>(j) * nu +
                              static_cast<std::size_t>(i)];
        out.expand(Vec3{h[0] / h[3], h[1] / h[3], h[2] / h[3]});
      }
  return out;
}

}  // namespace trivox
