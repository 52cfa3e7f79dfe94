// Untangling by L-BFGS on the interior control points (see untangle.h).
#include "trivox/construct/untangle.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/math.h"
#include "trivox/parallel.h"
#include "trivox/spline/detail/basis.h"
#include "trivox/spline/refine.h"

namespace trivox {
namespace {

// Basis values and derivatives of one direction at one sample: the `order` functions
// starting at control index `first`.
struct DirSample {
  int first = 0;
  std::vector<double> value, deriv;
};

// The Jacobian's columns (ju, jv, jw) at one sample of the volume whose control points are
// p (x, y, z per point, u fastest over nu x nv x ...), from the three directions' basis
// values and derivatives there.
void sample_jacobian(const double* p, int nu, int nv, const DirSample& su, const DirSample& sv, const DirSample& sw,
                     Vec3& ju, Vec3& jv, Vec3& jw) {
  ju = jv = jw = Vec3{0, 0, 0};
  const std::size_t ou = su.value.size(), ov = sv.value.size(), ow = sw.value.size();
  for (std::size_t c = 0; c < ow; ++c)
    for (std::size_t b = 0; b < ov; ++b)
      for (std::size_t a = 0; a < ou; ++a) {
        const std::size_t idx =
            static_cast<std::size_t>(su.first + static_cast<int>(a) +
                                     nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
        const Vec3 x{p[3 * idx], p[3 * idx + 1], p[3 * idx + 2]};
        const double du = su.deriv[a] * sv.value[b] * sw.value[c];
        const double dv = su.value[a] * sv.deriv[b] * sw.value[c];
        const double dw = su.value[a] * sv.value[b] * sw.deriv[c];
        ju = ju + du * x;
        jv = jv + dv * x;
        jw = jw + dw * x;
      }
}

std::vector<DirSample> sample_direction(const KnotVector& kv, int samples_per_span) {
  // Uniform samples within each distinct knot span, both domain ends included.
  std::vector<double> ts;
  const auto k = kv.knots();
  const double lo = kv.lo(), hi = kv.hi();
  for (std::size_t i = 0; i + 1 < k.size(); ++i) {
    const double a = std::max(k[i], lo), b = std::min(k[i + 1], hi);
    if (!(b > a)) continue;
    for (int s = 0; s < samples_per_span; ++s) ts.push_back(a + (b - a) * s / samples_per_span);
  }
  ts.push_back(hi);
  std::vector<DirSample> out;
  const int order = kv.order();
  for (double t : ts) {
    const int span = kv.find_span(t);
    DirSample d;
    d.first = span - order + 1;
    d.value.resize(static_cast<std::size_t>(order));
    d.deriv.resize(static_cast<std::size_t>(order));
    basis_first_derivatives(kv, span, t, d.value.data(), d.deriv.data());
    out.push_back(std::move(d));
  }
  return out;
}

// The straightforward objective, one sample at a time in (w, v, u) order: the reference the
// fast objective below is tested against (detail::untangle_objective_reference), bit for bit.
class ReferenceObjective {
 public:
  ReferenceObjective(const TensorSpline& s, int samples_per_span) {
    for (int d = 0; d < 3; ++d) {
      samples_[static_cast<std::size_t>(d)] = sample_direction(s.knots(d), samples_per_span);
      n_[static_cast<std::size_t>(d)] = s.num_ctrl(d);
    }
  }

  std::size_t num_samples() const { return samples_[0].size() * samples_[1].size() * samples_[2].size(); }

  // det J at every sample for control points `p` (3 per point, all points).
  std::vector<double> dets(const std::vector<double>& p) const {
    std::vector<double> out;
    out.reserve(num_samples());
    visit(p, [&](double det, const auto&) { out.push_back(det); });
    return out;
  }

  // F and its gradient (with respect to all points; the caller masks the boundary).
  double value_gradient(const std::vector<double>& p, double sigma, double scale, double target,
                        std::vector<double>* grad) const {
    double f = 0.0;
    if (grad) std::fill(grad->begin(), grad->end(), 0.0);
    visit(p, [&](double det, const auto& chain) {
      const double r = target - sigma * det / scale;
      if (r <= 0.0) return;
      f += r * r;
      if (grad) chain(-2.0 * r * sigma / scale, *grad);
    });
    return f;
  }

 private:
  // Calls fn(det, chain) at every sample; chain(c, g) adds c * d det / d P to g.
  template <class Fn>
  void visit(const std::vector<double>& p, Fn&& fn) const {
    const int nu = n_[0], nv = n_[1];
    for (const DirSample& sw : samples_[2])
      for (const DirSample& sv : samples_[1])
        for (const DirSample& su : samples_[0]) {
          Vec3 ju, jv, jw;
          sample_jacobian(p.data(), nu, nv, su, sv, sw, ju, jv, jw);
          const std::size_t ou = su.value.size(), ov = sv.value.size(), ow = sw.value.size();
          const Vec3 cvw = cross(jv, jw), cwu = cross(jw, ju), cuv = cross(ju, jv);
          const double det = dot(ju, cvw);
          auto chain = [&](double coeff, std::vector<double>& g) {
            for (std::size_t c = 0; c < ow; ++c)
              for (std::size_t b = 0; b < ov; ++b)
                for (std::size_t a = 0; a < ou; ++a) {
                  const std::size_t idx = static_cast<std::size_t>(
                      su.first + static_cast<int>(a) +
                      nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
                  const double du = su.deriv[a] * sv.value[b] * sw.value[c];
                  const double dv = su.value[a] * sv.deriv[b] * sw.value[c];
                  const double dw = su.value[a] * sv.value[b] * sw.deriv[c];
                  const Vec3 d = du * cvw + dv * cwu + dw * cuv;
                  g[3 * idx] += coeff * d.x;
                  g[3 * idx + 1] += coeff * d.y;
                  g[3 * idx + 2] += coeff * d.z;
                }
          };
          fn(det, chain);
        }
  }

  std::array<std::vector<DirSample>, 3> samples_;
  std::array<int, 3> n_{};
};

// Lanes of doubles (GCC's vector extension), as many as the target's vector registers hold
// (four with AVX, two with SSE2; wider vectors than the target has are split into slow scalar
// code). Each lane does exactly the scalar operations of one sample, in the same order, so its
// results are the reference's bit for bit.
#if defined(__AVX__)
constexpr int kLanes = 4;
#else
constexpr int kLanes = 2;
#endif
typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));

// The fast objective: the same sums as ReferenceObjective, computed in two passes.
//  1. det J at every sample, in parallel over the v samples, up to kLanes u samples of one knot
//     span at a time (they share their control points: each point is loaded once for them all).
//     Each det is the scalar expression of the reference, lane by lane.
//  2. F and its gradient from those dets, sequentially in the reference's sample order (the
//     order of every rounding in the sums), recomputing J only at the samples below the target
//     (few: the gradient is zero elsewhere).
class Objective {
 public:
  Objective(const TensorSpline& s, int samples_per_span, int threads) : threads_(threads) {
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      samples_[dd] = sample_direction(s.knots(d), samples_per_span);
      n_[dd] = s.num_ctrl(d);
      orders_[dd] = s.knots(d).order();
      cells_[dd] = n_[dd] - orders_[dd] + 1;
    }
    // The u samples in groups of at most kLanes sharing their first control point (one knot span).
    const std::vector<DirSample>& su = samples_[0];
    const std::size_t ou = static_cast<std::size_t>(s.knots(0).order());
    for (std::size_t i = 0; i < su.size();) {
      Group g;
      g.start = i;
      g.first = su[i].first;
      while (i < su.size() && g.count < kLanes && su[i].first == g.first) ++i, ++g.count;
      g.value.assign(ou, Lanes{});
      g.deriv.assign(ou, Lanes{});
      for (int l = 0; l < g.count; ++l)
        for (std::size_t a = 0; a < ou; ++a) {
          g.value[a][l] = su[g.start + static_cast<std::size_t>(l)].value[a];
          g.deriv[a][l] = su[g.start + static_cast<std::size_t>(l)].deriv[a];
        }
      groups_.push_back(std::move(g));
    }
  }

  std::size_t num_samples() const { return samples_[0].size() * samples_[1].size() * samples_[2].size(); }

  // det J at every sample for control points `p` (3 per point, all points), in the reference's
  // order: sample (iu, iv, iw) at iu + nu_s (iv + nv_s iw).
  //
  // Only the samples whose control points differ (in any bit) from those of the previous call
  // are computed again; the others keep their dets, which the same bits give again. Between
  // two steps of the line search, or two iterations, about 40 % of the duck's samples keep
  // theirs. Not for concurrent calls: the dets of the previous call are kept here.
  void dets(const std::vector<double>& p, std::vector<double>& out) const {
    const bool first = last_points_.size() != p.size();
    std::vector<std::uint8_t> changed(p.size() / 3, first ? 1 : 0);
    if (!first)
      for (std::size_t i = 0; i < p.size(); ++i)
        if (std::bit_cast<std::uint64_t>(p[i]) != std::bit_cast<std::uint64_t>(last_points_[i])) changed[i / 3] = 1;
    // A span cell (the samples whose first control points are fu, fv, fw) moved when one of
    // its order_u x order_v x order_w points did.
    const int nu = n_[0], nv = n_[1];
    moved_.assign(static_cast<std::size_t>(cells_[0] * cells_[1] * cells_[2]), 0);
    for (int fw = 0; fw < cells_[2]; ++fw)
      for (int fv = 0; fv < cells_[1]; ++fv)
        for (int fu = 0; fu < cells_[0]; ++fu) {
          bool moved = false;
          for (int c = 0; c < orders_[2] && !moved; ++c)
            for (int b = 0; b < orders_[1] && !moved; ++b)
              for (int a = 0; a < orders_[0] && !moved; ++a)
                moved = changed[static_cast<std::size_t>(fu + a + nu * (fv + b + nv * (fw + c)))] != 0;
          moved_[cell(fu, fv, fw)] = moved ? 1 : 0;
        }
    last_det_.resize(num_samples());
    parallel_for_each(samples_[1].size(), threads_, [&](std::size_t iv) { dets_at_v(p, iv, last_det_); });
    last_points_ = p;
    out = last_det_;
  }

  // F and its gradient (with respect to all points; the caller masks the boundary), from the
  // dets of `p` that dets() gave.
  double value_gradient(const std::vector<double>& p, const std::vector<double>& det, double sigma, double scale,
                        double target, std::vector<double>* grad) const {
    double f = 0.0;
    if (grad) std::fill(grad->begin(), grad->end(), 0.0);
    const int nu = n_[0], nv = n_[1];
    std::size_t k = 0;
    for (const DirSample& sw : samples_[2])
      for (const DirSample& sv : samples_[1])
        for (const DirSample& su : samples_[0]) {
          const double r = target - sigma * det[k++] / scale;
          if (r <= 0.0) continue;
          f += r * r;
          if (!grad) continue;
          // The reference's J, its cross products and its chain rule at this sample.
          Vec3 ju, jv, jw;
          sample_jacobian(p.data(), nu, nv, su, sv, sw, ju, jv, jw);
          const std::size_t ou = su.value.size(), ov = sv.value.size(), ow = sw.value.size();
          const Vec3 cvw = cross(jv, jw), cwu = cross(jw, ju), cuv = cross(ju, jv);
          const double coeff = -2.0 * r * sigma / scale;
          std::vector<double>& g = *grad;
          for (std::size_t c = 0; c < ow; ++c)
            for (std::size_t b = 0; b < ov; ++b)
              for (std::size_t a = 0; a < ou; ++a) {
                const std::size_t idx = static_cast<std::size_t>(
                    su.first + static_cast<int>(a) +
                    nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
                const double du = su.deriv[a] * sv.value[b] * sw.value[c];
                const double dv = su.value[a] * sv.deriv[b] * sw.value[c];
                const double dw = su.value[a] * sv.value[b] * sw.deriv[c];
                const Vec3 d = du * cvw + dv * cwu + dw * cuv;
                g[3 * idx] += coeff * d.x;
                g[3 * idx + 1] += coeff * d.y;
                g[3 * idx + 2] += coeff * d.z;
              }
        }
    return f;
  }

 private:
  // Up to kLanes consecutive u samples with the same first control point.
  struct Group {
    std::size_t start = 0;
    int count = 0, first = 0;
    std::vector<Lanes> value, deriv;  // per basis function a: the samples' values in lanes
  };

  // The dets of the samples with v sample `iv`, every u and w sample.
  void dets_at_v(const std::vector<double>& p, std::size_t iv, std::vector<double>& out) const {
    const int nu = n_[0], nv = n_[1];
    const DirSample& sv = samples_[1][iv];
    const std::size_t nus = samples_[0].size(), nvs = samples_[1].size();
    const std::size_t ov = sv.value.size();
    std::vector<Lanes> uv_du, uv_dv, uv_dw;
    for (const Group& g : groups_) {
      const std::size_t ou = g.value.size();
      // The reference's weights are (basis u * basis v) * basis w: the first products depend on
      // the u and v samples only, so they are formed once for every w sample.
      uv_du.resize(ou * ov);
      uv_dv.resize(ou * ov);
      uv_dw.resize(ou * ov);
      for (std::size_t b = 0; b < ov; ++b)
        for (std::size_t a = 0; a < ou; ++a) {
          uv_du[b * ou + a] = g.deriv[a] * sv.value[b];
          uv_dv[b * ou + a] = g.value[a] * sv.deriv[b];
          uv_dw[b * ou + a] = g.value[a] * sv.value[b];
        }
      for (std::size_t iw = 0; iw < samples_[2].size(); ++iw) {
        const DirSample& sw = samples_[2][iw];
        const std::size_t ow = sw.value.size();
        if (moved_[cell(g.first, sv.first, sw.first)] == 0) continue;  // the previous call's dets hold
        Lanes jux{}, juy{}, juz{}, jvx{}, jvy{}, jvz{}, jwx{}, jwy{}, jwz{};
        for (std::size_t c = 0; c < ow; ++c)
          for (std::size_t b = 0; b < ov; ++b)
            for (std::size_t a = 0; a < ou; ++a) {
              const std::size_t idx = static_cast<std::size_t>(
                  g.first + static_cast<int>(a) +
                  nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
              const double x = p[3 * idx], y = p[3 * idx + 1], z = p[3 * idx + 2];
              // As the reference: J += weight * point, coordinate by coordinate.
              const Lanes du = uv_du[b * ou + a] * sw.value[c];
              const Lanes dv = uv_dv[b * ou + a] * sw.value[c];
              const Lanes dw = uv_dw[b * ou + a] * sw.deriv[c];
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
        double* row = out.data() + (iw * nvs + iv) * nus;
        for (int l = 0; l < g.count; ++l) {
          const Vec3 ju{jux[l], juy[l], juz[l]}, jv{jvx[l], jvy[l], jvz[l]}, jw{jwx[l], jwy[l], jwz[l]};
          const Vec3 cvw = cross(jv, jw);
          row[g.start + static_cast<std::size_t>(l)] = dot(ju, cvw);
        }
      }
    }
  }

  std::array<std::vector<DirSample>, 3> samples_;
  std::array<int, 3> n_{};
  std::vector<Group> groups_;
  int threads_ = 0;
  std::size_t cell(int fu, int fv, int fw) const {
    return static_cast<std::size_t>(fu + cells_[0] * (fv + cells_[1] * fw));
  }

  std::array<int, 3> orders_{}, cells_{};  // per direction: the order, and n - order + 1 first points
  // The previous call's control points and dets, and the span cells whose points differ now.
  mutable std::vector<double> last_points_, last_det_;
  mutable std::vector<std::uint8_t> moved_;
};

TensorSpline refine_uniformly(TensorSpline s, int knots_per_span) {
  for (int d = 0; d < 3; ++d) {
    const std::vector<double> k(s.knots(d).knots().begin(), s.knots(d).knots().end());
    const double lo = s.lo(d), hi = s.hi(d);
    for (std::size_t i = 0; i + 1 < k.size(); ++i) {
      const double a = std::max(k[i], lo), b = std::min(k[i + 1], hi);
      if (!(b > a)) continue;
      for (int m = 1; m <= knots_per_span; ++m) s = insert_knot(s, d, a + (b - a) * m / (knots_per_span + 1));
    }
  }
  return s;
}

double dotv(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// The untangling, with the fast objective, or with the reference objective and without the
// stop at a zero gradient (detail::untangle_reference): the two give the same volume, bit for
// bit, which the tests check.
UntangleResult untangle_with(const TensorSpline& volume, const UntangleParams& params, bool reference) {
  if (volume.param_dim() != 3 || volume.point_dim() != 3)
    throw ModelError("untangle: expected a trivariate with 3D points");
  if (volume.is_rational())
    throw ModelError("untangle: the volume is rational; only polynomial volumes can be untangled");
  for (int d = 0; d < 3; ++d)
    if (volume.knots(d).is_periodic())
      throw ModelError("untangle: the volume is periodic; only clamped volumes can be untangled");
  if (params.knots_per_span < 0 || params.knots_per_span > 8)
    throw ModelError(fmt::format("untangle: knots_per_span must be 0 to 8, got {}", params.knots_per_span));
  if (params.samples_per_span < 1 || params.iterations < 0 || !(params.target_relative > 0.0))
    throw ModelError("untangle: samples_per_span >= 1, iterations >= 0 and target_relative > 0 are required");

  TensorSpline s = refine_uniformly(volume, params.knots_per_span);
  const int nu = s.num_ctrl(0), nv = s.num_ctrl(1), nw = s.num_ctrl(2);
  if (nu < 3 || nv < 3 || nw < 3)
    throw ModelError(fmt::format("untangle: the volume has no interior control points ({} x {} x {})", nu, nv, nw));

  std::vector<double> x(s.points().begin(), s.points().end());
  // Which coordinates may move: those of interior control points.
  std::vector<double> mask(x.size(), 0.0);
  for (int k = 1; k + 1 < nw; ++k)
    for (int j = 1; j + 1 < nv; ++j)
      for (int i = 1; i + 1 < nu; ++i)
        for (int c = 0; c < 3; ++c) mask[static_cast<std::size_t>(3 * s.ctrl_linear(i, j, k) + c)] = 1.0;

  std::optional<Objective> fast;
  std::optional<ReferenceObjective> slow;
  if (reference)
    slow.emplace(s, params.samples_per_span);
  else
    fast.emplace(s, params.samples_per_span, params.threads);
  // The dets at x, kept with x (the fast objective's F, its gradient and the statistics come
  // from them), and at the point evaluated last.
  std::vector<double> det_x, det_new;
  if (slow)
    det_x = slow->dets(x);
  else
    fast->dets(x, det_x);
  double sum = 0.0, abs_sum = 0.0;
  for (double d : det_x) {
    sum += d;
    abs_sum += std::abs(d);
  }
  const double sigma = sum < 0.0 ? -1.0 : 1.0;
  const double scale = abs_sum / static_cast<double>(det_x.size());
  if (!(scale > 0.0)) throw ModelError("untangle: det J vanishes at every sample (a flat volume)");
  const double target = params.target_relative;

  auto stats = [&](const std::vector<double>& p, int& below, double& min_rel) {
    below = 0;
    min_rel = INFINITY;
    for (double d : slow ? slow->dets(p) : det_x) {
      const double r = sigma * d / scale;
      if (r < target) ++below;
      min_rel = std::min(min_rel, r);
    }
  };
  // F at p, and its gradient; `det` receives the dets of p (the fast objective only).
  int evaluations = 1;  // the dets at x, from which F and its gradient at x come
  auto evaluate = [&](const std::vector<double>& p, std::vector<double>& det, std::vector<double>* grad) {
    ++evaluations;
    if (slow) return slow->value_gradient(p, sigma, scale, target, grad);
    fast->dets(p, det);
    return fast->value_gradient(p, det, sigma, scale, target, grad);
  };
  UntangleResult result{s, 0, 0, 0, 0, 0, 0};
  stats(x, result.below_target_before, result.min_relative_before);

  // L-BFGS (Nocedal and Wright, Algorithm 7.4) on the masked coordinates.
  std::vector<double> g(x.size()), gnew(x.size()), dir(x.size()), xnew(x.size());
  double f = slow ? slow->value_gradient(x, sigma, scale, target, &g)
                  : fast->value_gradient(x, det_x, sigma, scale, target, &g);
  for (std::size_t i = 0; i < g.size(); ++i) g[i] *= mask[i];
  std::deque<std::vector<double>> ss, ys;
  // y_m . s_m and, for the newest pair, s . y and y . y: the same every time the recursion asks,
  // so the fast path forms them once per pair (the reference forms them each time).
  std::deque<double> ys_ss;
  double newest_sy = 0.0, newest_yy = 0.0;
  const auto y_dot_s = [&](std::size_t m) { return slow ? dotv(ys[m], ss[m]) : ys_ss[m]; };
  const double diag = s.control_box().diagonal();
  int it = 0;
  for (; it < params.iterations && f > 0.0; ++it) {
    if (params.stop != nullptr && params.stop->load()) throw CancelledError("stopped while untangling a volume");
    // Two-loop recursion for dir = -H g.
    dir = g;
    std::vector<double> alpha(ss.size());
    for (std::size_t m = ss.size(); m-- > 0;) {
      alpha[m] = dotv(ss[m], dir) / y_dot_s(m);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] -= alpha[m] * ys[m][i];
    }
    double gamma;
    if (ss.empty()) {
      const double gn = std::sqrt(dotv(g, g));
      gamma = gn > 0.0 ? 1e-3 * diag / gn : 1.0;
    } else {
      gamma = slow ? dotv(ss.back(), ys.back()) / dotv(ys.back(), ys.back()) : newest_sy / newest_yy;
    }
    for (double& d : dir) d *= gamma;
    for (std::size_t m = 0; m < ss.size(); ++m) {
      const double beta = dotv(ys[m], dir) / y_dot_s(m);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] += ss[m][i] * (alpha[m] - beta);
    }
    for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -dir[i] * mask[i];
    double slope = dotv(g, dir);
    if (!(slope < 0.0)) {  // not a descent direction: restart from steepest descent
      ss.clear();
      ys.clear();
      ys_ss.clear();
      const double gn = std::sqrt(dotv(g, g));
      // A zero gradient (the samples still below the target are where no interior point can
      // move det J, such as a face that collapses to a line): x is where the descent ends. The
      // steepest descent from it would be 0 / 0 in every coordinate, and every step of the line
      // search NaN, so that it fails and ends the loop with x as it is; this ends it at once.
      if (!slow && !(gn > 0.0)) break;
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -g[i] * 1e-3 * diag / gn;
      slope = dotv(g, dir);
    }
    // Backtracking (Armijo) line search.
    double step = 1.0, fnew = f;
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries, step *= 0.5) {
      for (std::size_t i = 0; i < x.size(); ++i) xnew[i] = x[i] + step * dir[i];
      fnew = evaluate(xnew, det_new, &gnew);
      if (fnew <= f + 1e-4 * step * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    for (std::size_t i = 0; i < gnew.size(); ++i) gnew[i] *= mask[i];
    std::vector<double> sv(x.size()), yv(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      sv[i] = xnew[i] - x[i];
      yv[i] = gnew[i] - g[i];
    }
    const double sy = dotv(sv, yv);
    if (sy > 1e-300) {
      if (!slow) {
        ys_ss.push_back(dotv(yv, sv));
        newest_sy = sy;
        newest_yy = dotv(yv, yv);
      }
      ss.push_back(std::move(sv));
      ys.push_back(std::move(yv));
      if (ss.size() > 8) {
        ss.pop_front();
        ys.pop_front();
        if (!slow) ys_ss.pop_front();
      }
    }
    x.swap(xnew);
    g.swap(gnew);
    det_x.swap(det_new);
    f = fnew;
  }
  result.iterations = it;
  result.evaluations = evaluations;
  result.spline = TensorSpline(s.all_knots(), 3, x);
  stats(x, result.below_target_after, result.min_relative_after);
  return result;
}

}  // namespace

namespace detail {

double untangle_objective(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                          double target_relative, std::vector<double>* gradient) {
  const Objective obj(s, samples_per_span, 0);
  const std::vector<double> x(s.points().begin(), s.points().end());
  if (gradient) gradient->assign(x.size(), 0.0);
  std::vector<double> det;
  obj.dets(x, det);
  return obj.value_gradient(x, det, sigma, scale, target_relative, gradient);
}

double untangle_objective_reference(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                                    double target_relative, std::vector<double>* gradient) {
  const ReferenceObjective obj(s, samples_per_span);
  const std::vector<double> x(s.points().begin(), s.points().end());
  if (gradient) gradient->assign(x.size(), 0.0);
  return obj.value_gradient(x, sigma, scale, target_relative, gradient);
}

UntangleResult untangle_reference(const TensorSpline& volume, const UntangleParams& params) {
  return untangle_with(volume, params, true);
}

}  // namespace detail

UntangleResult untangle(const TensorSpline& volume, const UntangleParams& params) {
  return untangle_with(volume, params, false);
}

}  // namespace trivox
