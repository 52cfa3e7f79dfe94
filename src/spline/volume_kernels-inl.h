// The de Boor evaluation kernels of Volume, compiled once per SIMD target (included by
// volume_kernels.cpp inside its per-target namespace; see kernel_arithmetic-inl.h). Written
// once as templates over the orders per direction so that the common low orders (2 to 4:
// linear, quadratic, cubic) compile to fully unrolled, vectorised code; Order = 0 means
// "order known only at run time" (any order up to kMaxOrder).
#if defined(TRIVOX_VOLUME_KERNELS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef TRIVOX_VOLUME_KERNELS_INL_H_
#undef TRIVOX_VOLUME_KERNELS_INL_H_
#else
#define TRIVOX_VOLUME_KERNELS_INL_H_
#endif

// A2.2 (and the first-derivative step of basis_first_derivatives) with the order known at
// compile time, so the loops unroll; the run-time versions in basis.cpp do the same
// operations, here with their multiply-adds fused where the target fuses.
template <int K, bool kDerivs>
inline void basis_fixed(const KnotVector& kv, int span, double t, double* N, double* dN) noexcept {
  constexpr int p = K - 1;
  constexpr int top = kDerivs ? p - 1 : p;
  const double* U = kv.knots().data();
  double left[K], right[K];
  N[0] = 1.0;
  for (int j = 1; j <= top; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    // right[r+1] + left[j-r] = U[span+r+1] - U[span+1-j+r], a knot difference of length j.
    const double* inv = kv.inverse_differences(j) + (span + 1 - j);
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] * inv[r];
      N[r] = fused_multiply_add(right[r + 1], temp, saved);
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  if constexpr (kDerivs) {
    double lower[K];
    for (int q = 0; q < p; ++q) lower[q] = N[q];
    const double* inv = kv.inverse_differences(p);
    for (int r = 0; r <= p; ++r) {
      const int i = span - p + r;
      const double a = r > 0 ? lower[r - 1] * inv[i] : 0.0;
      const double b = r < p ? lower[r] * inv[i + 1] : 0.0;
      N[r] = fused_multiply_add(t - U[i], a, (U[i + p + 1] - t) * b);
      dN[r] = p * (a - b);
    }
  }
}

// Basis values (and derivatives) of compile-time order K along one direction.
template <int K>
struct Basis1 {
  static constexpr int kCap = K > 0 ? K : kMaxOrder;
  int order, first;
  double N[kCap], dN[kCap];

  template <bool kDerivs>
  void compute(const KnotVector& kv, double t) noexcept {
    order = K > 0 ? K : kv.order();
    t = t < kv.lo() ? kv.lo() : (t > kv.hi() ? kv.hi() : t);
    const int span = kv.find_span(t);
    first = span - (order - 1);
    if constexpr (K > 1)
      basis_fixed<K, kDerivs>(kv, span, t, N, dN);
    else if constexpr (kDerivs)
      basis_first_derivatives(kv, span, t, N, dN);
    else
      basis_functions(kv, span, t, N);
  }
};

template <int KU, int KV, int KW>
Vec3 evaluate_kernel(const VolumeData& d, Vec3 uvw) noexcept {
  Basis1<KU> bu;
  Basis1<KV> bv;
  Basis1<KW> bw;
  bu.template compute<false>(*d.knots[0], uvw.x);
  bv.template compute<false>(*d.knots[1], uvw.y);
  bw.template compute<false>(*d.knots[2], uvw.z);
  const int ku = KU > 0 ? KU : bu.order, kv = KV > 0 ? KV : bv.order, kw = KW > 0 ? KW : bw.order;
  V4 acc{};
  for (int c = 0; c < kw; ++c) {
    V4 plane{};
    for (int b = 0; b < kv; ++b) {
      const H* row = d.points + static_cast<std::size_t>(bw.first + c) * d.stride_w +
                     static_cast<std::size_t>(bv.first + b) * d.stride_v + static_cast<std::size_t>(bu.first);
      V4 line{};
      for (int a = 0; a < ku; ++a) line = multiply_add(bu.N[a], load_point(row[a]), line);
      plane = multiply_add(bv.N[b], line, plane);
    }
    acc = multiply_add(bw.N[c], plane, acc);
  }
  const double inv = 1.0 / acc[3];
  return {acc[0] * inv, acc[1] * inv, acc[2] * inv};
}

template <int KU, int KV, int KW>
void evaluate_jacobian_kernel(const VolumeData& d, Vec3 uvw, Vec3& value, Mat3& jac) noexcept {
  Basis1<KU> bu;
  Basis1<KV> bv;
  Basis1<KW> bw;
  bu.template compute<true>(*d.knots[0], uvw.x);
  bv.template compute<true>(*d.knots[1], uvw.y);
  bw.template compute<true>(*d.knots[2], uvw.z);
  // Contract u, then v, then w: S is the homogeneous value, Su/Sv/Sw its partials.
  const int ku = KU > 0 ? KU : bu.order, kv = KV > 0 ? KV : bv.order, kw = KW > 0 ? KW : bw.order;
  V4 S{}, Su{}, Sv{}, Sw{};
  for (int c = 0; c < kw; ++c) {
    V4 P{}, Pu{}, Pv{};
    for (int b = 0; b < kv; ++b) {
      const H* row = d.points + static_cast<std::size_t>(bw.first + c) * d.stride_w +
                     static_cast<std::size_t>(bv.first + b) * d.stride_v + static_cast<std::size_t>(bu.first);
      V4 L{}, Lu{};
      for (int a = 0; a < ku; ++a) {
        const V4 q = load_point(row[a]);
        L = multiply_add(bu.N[a], q, L);
        Lu = multiply_add(bu.dN[a], q, Lu);
      }
      P = multiply_add(bv.N[b], L, P);
      Pu = multiply_add(bv.N[b], Lu, Pu);
      Pv = multiply_add(bv.dN[b], L, Pv);
    }
    S = multiply_add(bw.N[c], P, S);
    Su = multiply_add(bw.N[c], Pu, Su);
    Sv = multiply_add(bw.N[c], Pv, Sv);
    Sw = multiply_add(bw.dN[c], P, Sw);
  }
  homogeneous_to_euclidean(S, Su, Sv, Sw, {1.0, 1.0, 1.0}, value, jac);
}

#endif  // include toggle
