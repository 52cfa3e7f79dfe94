// The untangling's objective, reference and fast (see untangle_objective.h).
#include "construct/untangle_objective.h"

#include <algorithm>
#include <bit>

#include "trivox/parallel.h"
#include "trivox/spline/detail/basis.h"

namespace trivox::detail {

std::vector<DirSample> sample_direction(const KnotVector& kv, int samples_per_span) {
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

namespace {

// Calls fn(idx, du, dv, dw) for every control point of the sample (su, sv, sw), w slowest:
// its index and the partials of its basis weight, (basis u * basis v) * basis w.
template <class Fn>
inline void for_each_weight(int nu, int nv, const DirSample& su, const DirSample& sv, const DirSample& sw, Fn&& fn) {
  const std::size_t ou = su.value.size(), ov = sv.value.size(), ow = sw.value.size();
  for (std::size_t c = 0; c < ow; ++c)
    for (std::size_t b = 0; b < ov; ++b)
      for (std::size_t a = 0; a < ou; ++a) {
        const std::size_t idx =
            static_cast<std::size_t>(su.first + static_cast<int>(a) +
                                     nu * (sv.first + static_cast<int>(b) + nv * (sw.first + static_cast<int>(c))));
        const double du = su.deriv[a] * sv.value[b] * sw.value[c];
        const double dv = su.value[a] * sv.deriv[b] * sw.value[c];
        const double dw = su.value[a] * sv.value[b] * sw.deriv[c];
        fn(idx, du, dv, dw);
      }
}

}  // namespace

SampleJacobian sample_jacobian(const double* p, int nu, int nv, const DirSample& su, const DirSample& sv,
                               const DirSample& sw) {
  SampleJacobian j;
  j.ju = j.jv = j.jw = Vec3{0, 0, 0};
  for_each_weight(nu, nv, su, sv, sw, [&](std::size_t idx, double du, double dv, double dw) {
    const Vec3 x{p[3 * idx], p[3 * idx + 1], p[3 * idx + 2]};
    j.ju = j.ju + du * x;
    j.jv = j.jv + dv * x;
    j.jw = j.jw + dw * x;
  });
  j.cvw = cross(j.jv, j.jw);
  j.cwu = cross(j.jw, j.ju);
  j.cuv = cross(j.ju, j.jv);
  return j;
}

void add_det_gradient(const SampleJacobian& j, int nu, int nv, const DirSample& su, const DirSample& sv,
                      const DirSample& sw, double coeff, std::vector<double>& g) {
  for_each_weight(nu, nv, su, sv, sw, [&](std::size_t idx, double du, double dv, double dw) {
    const Vec3 d = du * j.cvw + dv * j.cwu + dw * j.cuv;
    g[3 * idx] += coeff * d.x;
    g[3 * idx + 1] += coeff * d.y;
    g[3 * idx + 2] += coeff * d.z;
  });
}

ReferenceObjective::ReferenceObjective(const TensorSpline& s, int samples_per_span) {
  for (int d = 0; d < 3; ++d) {
    samples_[static_cast<std::size_t>(d)] = sample_direction(s.knots(d), samples_per_span);
    n_[static_cast<std::size_t>(d)] = s.num_ctrl(d);
  }
}

std::vector<double> ReferenceObjective::dets(const std::vector<double>& p) const {
  std::vector<double> out;
  out.reserve(num_samples());
  for (const DirSample& sw : samples_[2])
    for (const DirSample& sv : samples_[1])
      for (const DirSample& su : samples_[0]) {
        const SampleJacobian j = sample_jacobian(p.data(), n_[0], n_[1], su, sv, sw);
        out.push_back(dot(j.ju, j.cvw));
      }
  return out;
}

double ReferenceObjective::value_gradient(const std::vector<double>& p, double sigma, double scale, double target,
                                          std::vector<double>* grad) const {
  double f = 0.0;
  if (grad) std::fill(grad->begin(), grad->end(), 0.0);
  for (const DirSample& sw : samples_[2])
    for (const DirSample& sv : samples_[1])
      for (const DirSample& su : samples_[0]) {
        const SampleJacobian j = sample_jacobian(p.data(), n_[0], n_[1], su, sv, sw);
        const double r = target - sigma * dot(j.ju, j.cvw) / scale;
        if (r <= 0.0) continue;
        f += r * r;
        if (grad) add_det_gradient(j, n_[0], n_[1], su, sv, sw, -2.0 * r * sigma / scale, *grad);
      }
  return f;
}

Objective::Objective(const TensorSpline& s, int samples_per_span, int threads) : threads_(threads) {
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    t_.samples[dd] = sample_direction(s.knots(d), samples_per_span);
    t_.n[dd] = s.num_ctrl(d);
    t_.orders[dd] = s.knots(d).order();
    t_.cells[dd] = t_.n[dd] - t_.orders[dd] + 1;
  }
  const std::vector<DirSample>& su = t_.samples[0];
  const std::size_t ou = static_cast<std::size_t>(s.knots(0).order());
  for (std::size_t i = 0; i < su.size();) {
    UntangleTables::Group g;
    g.start = i;
    g.first = su[i].first;
    while (i < su.size() && g.count < kUntangleLanes && su[i].first == g.first) ++i, ++g.count;
    g.value.assign(ou * kUntangleLanes, 0.0);
    g.deriv.assign(ou * kUntangleLanes, 0.0);
    for (int l = 0; l < g.count; ++l)
      for (std::size_t a = 0; a < ou; ++a) {
        g.value[a * kUntangleLanes + static_cast<std::size_t>(l)] = su[g.start + static_cast<std::size_t>(l)].value[a];
        g.deriv[a * kUntangleLanes + static_cast<std::size_t>(l)] = su[g.start + static_cast<std::size_t>(l)].deriv[a];
      }
    t_.groups.push_back(std::move(g));
  }
}

void Objective::mark_moved(const std::vector<double>& p) const {
  const bool first = last_points_.size() != p.size();
  std::vector<std::uint8_t> changed(p.size() / 3, first ? 1 : 0);
  if (!first)
    for (std::size_t i = 0; i < p.size(); ++i)
      if (std::bit_cast<std::uint64_t>(p[i]) != std::bit_cast<std::uint64_t>(last_points_[i])) changed[i / 3] = 1;
  // A span cell (the samples whose first control points are fu, fv, fw) moved when one of
  // its order_u x order_v x order_w points did.
  const int nu = t_.n[0], nv = t_.n[1];
  t_.moved.assign(static_cast<std::size_t>(t_.cells[0] * t_.cells[1] * t_.cells[2]), 0);
  for (int fw = 0; fw < t_.cells[2]; ++fw)
    for (int fv = 0; fv < t_.cells[1]; ++fv)
      for (int fu = 0; fu < t_.cells[0]; ++fu) {
        bool moved = false;
        for (int c = 0; c < t_.orders[2] && !moved; ++c)
          for (int b = 0; b < t_.orders[1] && !moved; ++b)
            for (int a = 0; a < t_.orders[0] && !moved; ++a)
              moved = changed[static_cast<std::size_t>(fu + a + nu * (fv + b + nv * (fw + c)))] != 0;
        t_.moved[t_.cell(fu, fv, fw)] = moved ? 1 : 0;
      }
}

void Objective::dets(const std::vector<double>& p, std::vector<double>& out) const {
  mark_moved(p);
  last_det_.resize(num_samples());
  parallel_for_each(t_.samples[1].size(), threads_,
                    [&](std::size_t iv) { untangle_dets_at_v(t_, p.data(), iv, last_det_.data()); });
  last_points_ = p;
  out = last_det_;
}

double Objective::value_gradient(const std::vector<double>& p, const std::vector<double>& det, double sigma,
                                 double scale, double target, std::vector<double>* grad) const {
  double f = 0.0;
  if (grad) std::fill(grad->begin(), grad->end(), 0.0);
  const int nu = t_.n[0], nv = t_.n[1];
  std::size_t k = 0;
  for (const DirSample& sw : t_.samples[2])
    for (const DirSample& sv : t_.samples[1])
      for (const DirSample& su : t_.samples[0]) {
        const double r = target - sigma * det[k++] / scale;
        if (r <= 0.0) continue;
        f += r * r;
        if (!grad) continue;
        // The reference's J, its cross products and its chain rule at this sample.
        const SampleJacobian j = sample_jacobian(p.data(), nu, nv, su, sv, sw);
        add_det_gradient(j, nu, nv, su, sv, sw, -2.0 * r * sigma / scale, *grad);
      }
  return f;
}

}  // namespace trivox::detail
