// Untangling by L-BFGS on the interior control points (see untangle.h).
#include "trivox/construct/untangle.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/math.h"
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

class Objective {
 public:
  Objective(const TensorSpline& s, int samples_per_span) {
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
          Vec3 ju{0, 0, 0}, jv{0, 0, 0}, jw{0, 0, 0};
          const std::size_t ou = su.value.size(), ov = sv.value.size(), ow = sw.value.size();
          for (std::size_t c = 0; c < ow; ++c)
            for (std::size_t b = 0; b < ov; ++b)
              for (std::size_t a = 0; a < ou; ++a) {
                const std::size_t idx = static_cast<std::size_t>(
                    su.first + static_cast<int>(a) +
                    nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
                const Vec3 x{p[3 * idx], p[3 * idx + 1], p[3 * idx + 2]};
                const double du = su.deriv[a] * sv.value[b] * sw.value[c];
                const double dv = su.value[a] * sv.deriv[b] * sw.value[c];
                const double dw = su.value[a] * sv.value[b] * sw.deriv[c];
                ju = ju + du * x;
                jv = jv + dv * x;
                jw = jw + dw * x;
              }
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

}  // namespace

namespace detail {
double untangle_objective(const TensorSpline& s, int samples_per_span, double sigma, double scale,
                          double target_relative, std::vector<double>* gradient) {
  const Objective obj(s, samples_per_span);
  const std::vector<double> x(s.points().begin(), s.points().end());
  if (gradient) gradient->assign(x.size(), 0.0);
  return obj.value_gradient(x, sigma, scale, target_relative, gradient);
}
}  // namespace detail

UntangleResult untangle(const TensorSpline& volume, const UntangleParams& params) {
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

  const Objective obj(s, params.samples_per_span);
  const std::vector<double> d0 = obj.dets(x);
  double sum = 0.0, abs_sum = 0.0;
  for (double d : d0) {
    sum += d;
    abs_sum += std::abs(d);
  }
  const double sigma = sum < 0.0 ? -1.0 : 1.0;
  const double scale = abs_sum / static_cast<double>(d0.size());
  if (!(scale > 0.0)) throw ModelError("untangle: det J vanishes at every sample (a flat volume)");
  const double target = params.target_relative;

  auto stats = [&](const std::vector<double>& p, int& below, double& min_rel) {
    below = 0;
    min_rel = INFINITY;
    for (double d : obj.dets(p)) {
      const double r = sigma * d / scale;
      if (r < target) ++below;
      min_rel = std::min(min_rel, r);
    }
  };
  UntangleResult result{s, 0, 0, 0, 0, 0};
  stats(x, result.below_target_before, result.min_relative_before);

  // L-BFGS (Nocedal and Wright, Algorithm 7.4) on the masked coordinates.
  std::vector<double> g(x.size()), gnew(x.size()), dir(x.size()), xnew(x.size());
  double f = obj.value_gradient(x, sigma, scale, target, &g);
  for (std::size_t i = 0; i < g.size(); ++i) g[i] *= mask[i];
  std::deque<std::vector<double>> ss, ys;
  const double diag = s.control_box().diagonal();
  int it = 0;
  for (; it < params.iterations && f > 0.0; ++it) {
    if (params.stop != nullptr && params.stop->load()) throw CancelledError("stopped while untangling a volume");
    // Two-loop recursion for dir = -H g.
    dir = g;
    std::vector<double> alpha(ss.size());
    for (std::size_t m = ss.size(); m-- > 0;) {
      alpha[m] = dotv(ss[m], dir) / dotv(ys[m], ss[m]);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] -= alpha[m] * ys[m][i];
    }
    double gamma;
    if (ss.empty()) {
      const double gn = std::sqrt(dotv(g, g));
      gamma = gn > 0.0 ? 1e-3 * diag / gn : 1.0;
    } else {
      gamma = dotv(ss.back(), ys.back()) / dotv(ys.back(), ys.back());
    }
    for (double& d : dir) d *= gamma;
    for (std::size_t m = 0; m < ss.size(); ++m) {
      const double beta = dotv(ys[m], dir) / dotv(ys[m], ss[m]);
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] += ss[m][i] * (alpha[m] - beta);
    }
    for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -dir[i] * mask[i];
    double slope = dotv(g, dir);
    if (!(slope < 0.0)) {  // not a descent direction: restart from steepest descent
      ss.clear();
      ys.clear();
      const double gn = std::sqrt(dotv(g, g));
      for (std::size_t i = 0; i < dir.size(); ++i) dir[i] = -g[i] * 1e-3 * diag / gn;
      slope = dotv(g, dir);
    }
    // Backtracking (Armijo) line search.
    double step = 1.0, fnew = f;
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries, step *= 0.5) {
      for (std::size_t i = 0; i < x.size(); ++i) xnew[i] = x[i] + step * dir[i];
      fnew = obj.value_gradient(xnew, sigma, scale, target, &gnew);
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
    if (dotv(sv, yv) > 1e-300) {
      ss.push_back(std::move(sv));
      ys.push_back(std::move(yv));
      if (ss.size() > 8) {
        ss.pop_front();
        ys.pop_front();
      }
    }
    x.swap(xnew);
    g.swap(gnew);
    f = fnew;
  }
  result.iterations = it;
  result.spline = TensorSpline(s.all_knots(), 3, x);
  stats(x, result.below_target_after, result.min_relative_after);
  return result;
}

}  // namespace trivox
