// Sweep of a planar section along a path: stations in a rotation-minimising frame (double
// reflection), interpolated along w (see sweep.h for the method and what is approximate).
#include "trivox/construct/sweep.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "construct/construct_util.h"
#include "trivox/error.h"
#include "trivox/spline/detail/basis.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox {

namespace {

struct Station {
  Vec3 point, tangent, normal;  // unit tangent; normal: unit, orthogonal to the tangent
};

Station evaluate_path(const TensorSpline& path, double t, double scale) {
  double x[3], d[3];
  const double tt[1] = {t};
  path.evaluate_with_partials(tt, x, d);
  const Vec3 tangent{d[0], d[1], d[2]};
  if (!(norm(tangent) > 1e-12 * scale))
    throw ModelError(fmt::format("the sweep path has no tangent at parameter {} (its derivative vanishes)", t));
  return {{x[0], x[1], x[2]}, (1.0 / norm(tangent)) * tangent, {}};
}

Vec3 reflect(Vec3 v, Vec3 n, double nn) { return v - (2.0 * dot(n, v) / nn) * n; }

// The frame at b carried over from a by two reflections (Wang et al. 2008, Algorithm 1).
Vec3 double_reflection(const Station& a, const Station& b) {
  const Vec3 v1 = b.point - a.point;
  const double c1 = dot(v1, v1);
  Vec3 r = a.normal, t = a.tangent;
  if (c1 > 0) {
    r = reflect(r, v1, c1);
    t = reflect(t, v1, c1);
  }
  const Vec3 v2 = b.tangent - t;
  const double c2 = dot(v2, v2);
  if (c2 > 0) r = reflect(r, v2, c2);
  // Remove rounding drift: keep the normal unit and orthogonal to the tangent.
  r = r - dot(r, b.tangent) * b.tangent;
  return (1.0 / norm(r)) * r;
}

Vec3 rotate_about(Vec3 v, Vec3 axis, double angle) {
  return std::cos(angle) * v + std::sin(angle) * cross(axis, v) + (1 - std::cos(angle)) * dot(axis, v) * axis;
}

// The stations at parameters ts, with normals carried by double reflection from `first`.
std::vector<Station> frames(const TensorSpline& path, const std::vector<double>& ts, Vec3 first, double scale) {
  std::vector<Station> st;
  for (double t : ts) st.push_back(evaluate_path(path, t, scale));
  st[0].normal = first;
  for (std::size_t k = 1; k < st.size(); ++k) st[k].normal = double_reflection(st[k - 1], st[k]);
  return st;
}

// Section control points placed in the frame of a station, turned by `angle` about the
// tangent: 3 coordinates per control point appended to `out`.
void place(const std::vector<Vec3>& local, const Station& s, double angle, std::vector<double>& out) {
  const Vec3 n = rotate_about(s.normal, s.tangent, angle);
  const Vec3 b = cross(s.tangent, n);
  for (const Vec3& q : local) {
    const Vec3 p = s.point + q.x * n + q.y * b;
    out.insert(out.end(), {p.x, p.y, p.z});
  }
}

}  // namespace

Constructed sweep(const TensorSpline& section_in, const TensorSpline& path_in, const SweepParams& params) {
  const TensorSpline section = detail::checked_surface(section_in, "swept section");
  if (path_in.param_dim() != 1 || path_in.point_dim() != 3)
    throw ModelError(
        fmt::format("the sweep path must be a curve (1 parameter) with 3D points, not {} parameter(s) "
                    "and {} coordinate(s)",
                    path_in.param_dim(), path_in.point_dim()));
  if (params.stations < 4) throw ModelError(fmt::format("a sweep needs at least 4 stations, not {}", params.stations));
  const TensorSpline path = clamped(path_in);
  const Box3 section_box = section.control_box();
  const double section_size = std::max(section_box.diagonal(), 1e-300);
  std::vector<Vec3> local;
  for (int p = 0; p < section.total_ctrl(); ++p) {
    const Vec3 q = detail::to_vec3(section.points().subspan(static_cast<std::size_t>(3 * p), 3));
    if (std::abs(q.z) > 1e-9 * section_size)
      throw ModelError(
          fmt::format("the swept section must lie in its plane z = 0: control point {} has z = {}", p, q.z));
    local.push_back(q);
  }
  const double scale = std::max(path.control_box().diagonal(), section_size);

  const int n = params.stations;
  const double lo = path.lo(0), hi = path.hi(0);
  std::vector<double> ts(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) ts[static_cast<std::size_t>(k)] = lo + (hi - lo) * k / (n - 1);
  const Station start = evaluate_path(path, lo, scale);
  Vec3 x0 = params.initial_x.value_or(Vec3{});
  if (!params.initial_x) {
    const Vec3 t = start.tangent;
    x0 = (std::abs(t.x) <= std::abs(t.y) && std::abs(t.x) <= std::abs(t.z)) ? Vec3{1, 0, 0}
         : (std::abs(t.y) <= std::abs(t.z))                                 ? Vec3{0, 1, 0}
                                                                            : Vec3{0, 0, 1};
  }
  x0 = x0 - dot(x0, start.tangent) * start.tangent;
  x0 = detail::unit(x0, "the initial x direction of the section (projected normal to the path's tangent)");
  std::vector<Station> st = frames(path, ts, x0, scale);

  // A closed path: spread the frame's rotation between the end and the start along the path.
  double closing = 0.0;
  const Station& end = st.back();
  if (norm(end.point - st.front().point) <= 1e-9 * scale && dot(end.tangent, st.front().tangent) > 1 - 1e-9)
    closing = std::atan2(dot(cross(end.normal, st.front().normal), end.tangent), dot(end.normal, st.front().normal));
  const double twist = params.twist_deg * std::numbers::pi / 180.0;
  const auto angle_at = [&](double f) { return f * (closing + twist); };

  // Placements, one row of 3 * ctrl values per station, interpolated along w.
  std::vector<double> rows;
  for (int k = 0; k < n; ++k)
    place(local, st[static_cast<std::size_t>(k)], angle_at(static_cast<double>(k) / (n - 1)), rows);
  std::vector<double> s(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) s[static_cast<std::size_t>(k)] = static_cast<double>(k) / (n - 1);
  const int order = std::min(4, n);
  const int p = order - 1;
  std::vector<double> knots(static_cast<std::size_t>(order), 0.0);
  for (int j = 1; j < n - p; ++j) {  // averaging (The NURBS Book, Eq. 9.8)
    double a = 0;
    for (int i = j; i < j + p; ++i) a += s[static_cast<std::size_t>(i)];
    knots.push_back(a / p);
  }
  knots.insert(knots.end(), static_cast<std::size_t>(order), 1.0);
  const KnotVector kw(order, std::move(knots));
  const int dim = 3 * section.total_ctrl();
  const std::vector<double> ctrl = interpolate_values(kw, s, rows, dim);

  std::vector<KnotVector> kvs = section.all_knots();
  kvs.push_back(kw);
  std::vector<double> weights;
  for (int k = 0; k < n && section.is_rational(); ++k)
    weights.insert(weights.end(), section.weights().begin(), section.weights().end());
  TensorSpline volume(std::move(kvs), 3, ctrl, std::move(weights));

  // Deviation at the midpoints between stations: the placement the construction aims at
  // (the frame carried on from the station before, the twist at that parameter) against the
  // interpolated control points there.
  double error = 0.0;
  std::vector<double> ideal, got(static_cast<std::size_t>(dim));
  for (int k = 0; k + 1 < n; ++k) {
    const double f = (k + 0.5) / (n - 1);
    Station mid = evaluate_path(path, lo + (hi - lo) * f, scale);
    mid.normal = double_reflection(st[static_cast<std::size_t>(k)], mid);
    ideal.clear();
    place(local, mid, angle_at(f), ideal);
    const int span = kw.find_span(f);
    std::array<double, kMaxOrder> N{};
    basis_functions(kw, span, f, N.data());
    std::fill(got.begin(), got.end(), 0.0);
    for (int j = 0; j < order; ++j) {
      const auto row = static_cast<std::size_t>(span - order + 1 + j) * static_cast<std::size_t>(dim);
      for (std::size_t c = 0; c < got.size(); ++c) got[c] += N[static_cast<std::size_t>(j)] * ctrl[row + c];
    }
    for (std::size_t c = 0; c < got.size(); c += 3)
      error = std::max(error, norm(Vec3{got[c] - ideal[c], got[c + 1] - ideal[c + 1], got[c + 2] - ideal[c + 2]}));
  }
  return detail::finish("sweep", std::move(volume), params.check, false, error);
}

}  // namespace trivox
