// Thick shell: the surface and its offset, the offset interpolated at Greville abscissae in
// the refined spline space of the surface (see shell.h).
#include "trivox/construct/shell.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "construct/construct_util.h"
#include "trivox/error.h"
#include "trivox/limits.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox {

namespace {

// Evaluates the surface and its unit normal at (u, v). Where the normal vanishes (a
// collapsed edge) it is taken a little way towards the middle of the domain.
void point_and_normal(const TensorSpline& s, double u, double v, Vec3& point, Vec3& normal) {
  const double cu = 0.5 * (s.lo(0) + s.hi(0)), cv = 0.5 * (s.lo(1) + s.hi(1));
  const double scale = std::max(s.control_box().diagonal(), 1e-300);
  for (double nudge : {0.0, 1e-7, 1e-5, 1e-3}) {
    const double t[2] = {u + nudge * (cu - u), v + nudge * (cv - v)};
    double x[3], d[6];
    s.evaluate_with_partials(t, x, d);
    const Vec3 n = cross(Vec3{d[0], d[1], d[2]}, Vec3{d[3], d[4], d[5]});
    if (nudge == 0.0) point = {x[0], x[1], x[2]};
    if (norm(n) > 1e-12 * scale * scale) {
      normal = (1.0 / norm(n)) * n;
      return;
    }
  }
  throw ModelError(fmt::format("the surface has no normal at (u, v) = ({}, {}) nor near it", u, v));
}

// The offset S + d n represented in s's space with s's weights: interpolation of the
// homogeneous offset at the Greville abscissae, u first, then v.
TensorSpline offset(const TensorSpline& s, double d) {
  if (d == 0.0) return s;
  const KnotVector &ku = s.knots(0), &kv = s.knots(1);
  const std::vector<double> xu = greville_abscissae(ku), xv = greville_abscissae(kv);
  const std::size_t nu = xu.size(), nv = xv.size();
  const TensorSpline wfun =
      s.is_rational() ? TensorSpline(s.all_knots(), 1, std::vector<double>(s.weights().begin(), s.weights().end())) : s;
  // values[i][j][c], i (u) major, for the solve along u with nv * 3 columns.
  std::vector<double> values(nu * nv * 3);
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i) {
      Vec3 p, n;
      point_and_normal(s, xu[i], xv[j], p, n);
      double w = 1.0;
      if (s.is_rational()) {
        const double t[2] = {xu[i], xv[j]};
        wfun.evaluate(t, std::span<double>(&w, 1));
      }
      const Vec3 q = w * (p + d * n);
      for (int c = 0; c < 3; ++c) values[(i * nv + j) * 3 + static_cast<std::size_t>(c)] = q[c];
    }
  const std::vector<double> along_u = interpolate_values(ku, xu, values, static_cast<int>(nv * 3));
  std::vector<double> transposed(nu * nv * 3);  // j major
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t c = 0; c < 3; ++c) transposed[(j * nu + i) * 3 + c] = along_u[(i * nv + j) * 3 + c];
  const std::vector<double> h = interpolate_values(kv, xv, transposed, static_cast<int>(nu * 3));
  // h is j major, u fastest: the control layout; divide by the control weights.
  std::vector<double> pts(h);
  for (std::size_t p = 0; p < nu * nv; ++p) {
    const double w = s.is_rational() ? s.weights()[p] : 1.0;
    for (std::size_t c = 0; c < 3; ++c) pts[3 * p + c] = h[3 * p + c] / w;
  }
  return TensorSpline(s.all_knots(), 3, std::move(pts), std::vector<double>(s.weights().begin(), s.weights().end()));
}

// The largest distance between `o` and the true offset S + d n on a grid of 4 samples per
// knot span between the Greville abscissae.
double offset_error(const TensorSpline& s, const TensorSpline& o, double d) {
  if (d == 0.0) return 0.0;
  std::vector<double> us, vs;
  for (int dir = 0; dir < 2; ++dir) {
    std::vector<double>& t = dir == 0 ? us : vs;
    const std::vector<double> xi = greville_abscissae(s.knots(dir));
    for (std::size_t i = 0; i + 1 < xi.size(); ++i)
      for (int q = 0; q < 4; ++q) t.push_back(xi[i] + (xi[i + 1] - xi[i]) * (q + 0.5) / 4);
  }
  double worst = 0.0;
  for (double v : vs)
    for (double u : us) {
      Vec3 p, n;
      point_and_normal(s, u, v, p, n);
      const double t[2] = {u, v};
      double x[3];
      o.evaluate(t, x);
      worst = std::max(worst, norm(Vec3{x[0], x[1], x[2]} - (p + d * n)));
    }
  return worst;
}

}  // namespace

std::optional<ShellSide> shell_side_from_name(std::string_view name) noexcept {
  if (name == "outside") return ShellSide::kOutside;
  if (name == "inside") return ShellSide::kInside;
  if (name == "centred" || name == "centered") return ShellSide::kCentred;
  return std::nullopt;
}

Constructed thick_shell(const TensorSpline& surface, const ShellParams& params) {
  TensorSpline s = detail::checked_surface(surface, "shell's surface");
  if (!(params.thickness_mm > 0.0) || !std::isfinite(params.thickness_mm))
    throw ModelError(fmt::format("the shell thickness {} mm is not > 0", params.thickness_mm));
  if (params.thickness_mm > kMaxModelNumber)
    throw ModelError(
        fmt::format("the shell thickness {:g} mm overflows: lengths beyond {:g} mm overflow in the "
                    "offset's det J",
                    params.thickness_mm, kMaxModelNumber));
  if (params.knots_per_span < 0 || params.knots_per_span > 8)
    throw ModelError(fmt::format("knots_per_span {} is outside [0, 8]", params.knots_per_span));
  for (int dir = 0; dir < 2; ++dir) {
    std::vector<double> breaks{s.lo(dir)};
    for (double b : s.knots(dir).interior_breaks()) breaks.push_back(b);
    breaks.push_back(s.hi(dir));
    for (std::size_t i = 0; i + 1 < breaks.size(); ++i)
      for (int q = 1; q <= params.knots_per_span; ++q)
        s = insert_knot(s, dir, breaks[i] + (breaks[i + 1] - breaks[i]) * q / (params.knots_per_span + 1));
  }
  const double t = params.thickness_mm;
  const double d0 = params.side == ShellSide::kOutside ? 0.0 : params.side == ShellSide::kInside ? -t : -0.5 * t;
  const double d1 = d0 + t;
  const TensorSpline inner = offset(s, d0), outer = offset(s, d1);
  const double error = std::max(offset_error(s, inner, d0), offset_error(s, outer, d1));
  return detail::finish("shell", detail::stack_layers({inner, outer}, KnotVector::bezier(2)), params.check, false,
                        error);
}

}  // namespace trivox
