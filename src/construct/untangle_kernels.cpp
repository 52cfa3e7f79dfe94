// The untangling's dets, compiled once per SIMD target: this file includes itself through
// HWY_TARGET_INCLUDE for every target Highway's foreach_target.h enables, and
// untangle_dets_at_v at its end calls the best target's version (docs/ARCHITECTURE.md,
// "SIMD targets"). The four lanes of a V4 hold four u samples; each lane does the reference's
// multiplies and adds for its sample, in the reference's order, and nothing is fused
// (-ffp-contract=off), so every target gives the reference's bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "construct/untangle_kernels.cpp"
#include <hwy/foreach_target.h>  // must precede highway.h
#include <hwy/highway.h>

#include <cstring>
#include <vector>

#include "construct/untangle_objective.h"
#include "trivox/spline/detail/homogeneous.h"

HWY_BEFORE_NAMESPACE();
namespace trivox::detail {
namespace HWY_NAMESPACE {

static_assert(kUntangleLanes * sizeof(double) == sizeof(V4), "a group's lanes are one V4");

// Lanes are kept in plain double arrays between uses (a V4 is not stored in memory that
// other targets' code allocates) and loaded and stored by copy.
inline V4 load_lanes(const double* lanes) noexcept {
  V4 v;
  std::memcpy(&v, lanes, sizeof v);
  return v;
}
inline void store_lanes(const V4& v, double* lanes) noexcept { std::memcpy(lanes, &v, sizeof v); }

void dets_at_v(const UntangleTables& t, const double* p, std::size_t iv, double* out) {
  const int nu = t.n[0], nv = t.n[1];
  const DirSample& sv = t.samples[1][iv];
  const std::size_t nus = t.samples[0].size(), nvs = t.samples[1].size();
  const std::size_t ov = sv.value.size();
  constexpr std::size_t kL = kUntangleLanes;
  std::vector<double> uv_du, uv_dv, uv_dw;  // per (a, b): kL lanes
  for (const UntangleTables::Group& g : t.groups) {
    const std::size_t ou = g.value.size() / kL;
    // The reference's weights are (basis u * basis v) * basis w: the first products depend on
    // the u and v samples only, so they are formed once for every w sample.
    uv_du.resize(ou * ov * kL);
    uv_dv.resize(ou * ov * kL);
    uv_dw.resize(ou * ov * kL);
    for (std::size_t b = 0; b < ov; ++b)
      for (std::size_t a = 0; a < ou; ++a) {
        const V4 value = load_lanes(&g.value[a * kL]), deriv = load_lanes(&g.deriv[a * kL]);
        store_lanes(deriv * sv.value[b], &uv_du[(b * ou + a) * kL]);
        store_lanes(value * sv.deriv[b], &uv_dv[(b * ou + a) * kL]);
        store_lanes(value * sv.value[b], &uv_dw[(b * ou + a) * kL]);
      }
    for (std::size_t iw = 0; iw < t.samples[2].size(); ++iw) {
      const DirSample& sw = t.samples[2][iw];
      const std::size_t ow = sw.value.size();
      if (t.moved[t.cell(g.first, sv.first, sw.first)] == 0) continue;  // the previous call's dets hold
      V4 jux{}, juy{}, juz{}, jvx{}, jvy{}, jvz{}, jwx{}, jwy{}, jwz{};
      for (std::size_t c = 0; c < ow; ++c)
        for (std::size_t b = 0; b < ov; ++b)
          for (std::size_t a = 0; a < ou; ++a) {
            const std::size_t idx =
                static_cast<std::size_t>(g.first + static_cast<int>(a) +
                                         nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
            const double x = p[3 * idx], y = p[3 * idx + 1], z = p[3 * idx + 2];
            // As the reference: J += weight * point, coordinate by coordinate.
            const V4 du = load_lanes(&uv_du[(b * ou + a) * kL]) * sw.value[c];
            const V4 dv = load_lanes(&uv_dv[(b * ou + a) * kL]) * sw.value[c];
            const V4 dw = load_lanes(&uv_dw[(b * ou + a) * kL]) * sw.deriv[c];
            jux = jux + du * x;
            juy = juy + du * y;
            juz = juz + du * z;
            jvx = jvx + dv * x;
            jvy = jvy + dv * y;
            jvz = jvz + dv * z;
            jwx = jwx + dw * x;
            jwy = jwy + dw * y;
            jwz = jwz + dw * z;
          }
      double* row = out + (iw * nvs + iv) * nus;
      for (int l = 0; l < g.count; ++l) {
        const Vec3 ju{jux[l], juy[l], juz[l]}, jv{jvx[l], jvy[l], jvz[l]}, jw{jwx[l], jwy[l], jwz[l]};
        const Vec3 cvw = cross(jv, jw);
        row[g.start + static_cast<std::size_t>(l)] = dot(ju, cvw);
      }
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace trivox::detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace trivox::detail {

HWY_EXPORT(dets_at_v);

void untangle_dets_at_v(const UntangleTables& t, const double* p, std::size_t iv, double* out) {
  HWY_DYNAMIC_DISPATCH(dets_at_v)(t, p, iv, out);
}

}  // namespace trivox::detail
#endif  // HWY_ONCE
