// Volume of revolution (The NURBS Book, Section 8.5, A8.1, applied to every control point of
// a profile surface instead of a profile curve).
#include "trivox/construct/revolve.h"

#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "construct/construct_util.h"
#include "trivox/error.h"
#include "trivox/spline/respace.h"

namespace trivox {

Constructed revolve(const TensorSpline& profile, const RevolveParams& params) {
  const TensorSpline s = detail::checked_surface(profile, "revolved profile");
  const Vec3 a = detail::unit(params.axis_dir, "the axis direction");
  const Vec3 o = params.axis_point_mm;
  if (!(params.angle_deg > 0.0 && params.angle_deg <= 360.0))
    throw ModelError(fmt::format("the angle {} degrees is outside (0, 360]", params.angle_deg));
  if (params.angle_direction < 0 || params.angle_direction > 2)
    throw ModelError(fmt::format("the angle direction {} is not 0 (u), 1 (v) or 2 (w)", params.angle_direction));

  // Arcs of at most 90 degrees: 2 * arcs + 1 control points, knots doubled at the joints.
  const double theta = params.angle_deg * std::numbers::pi / 180.0;
  const int arcs = std::max(1, static_cast<int>(std::ceil(params.angle_deg / 90.0 - 1e-9)));
  const double dtheta = theta / arcs;
  const double wm = std::cos(dtheta / 2);
  std::vector<double> knots(3, 0.0);
  for (int i = 1; i < arcs; ++i) knots.insert(knots.end(), 2, static_cast<double>(i) / arcs);
  knots.insert(knots.end(), 3, 1.0);
  const KnotVector kw(3, std::move(knots));
  const int na = 2 * arcs + 1;

  const int n = s.total_ctrl();
  std::vector<double> pts(static_cast<std::size_t>(n * na * 3));
  std::vector<double> wts(static_cast<std::size_t>(n * na));
  for (int p = 0; p < n; ++p) {
    const Vec3 P = detail::to_vec3(s.points().subspan(static_cast<std::size_t>(3 * p), 3));
    const double wp = s.is_rational() ? s.weights()[static_cast<std::size_t>(p)] : 1.0;
    const Vec3 O = o + dot(P - o, a) * a;  // foot on the axis
    const Vec3 X = P - O;                  // radius vector at angle 0
    const Vec3 Y = cross(a, X);            // the same length, 90 degrees ahead
    for (int k = 0; k < na; ++k) {
      // Even k: on the circle at angle k/2 * dtheta. Odd k: the tangents' intersection
      // between its neighbours, at distance r / cos(dtheta / 2), weight cos(dtheta / 2).
      const double ang = 0.5 * k * dtheta;
      const double scale = (k % 2 == 0) ? 1.0 : 1.0 / wm;
      const Vec3 Q = O + scale * (std::cos(ang) * X + std::sin(ang) * Y);
      const std::size_t idx = static_cast<std::size_t>(p + n * k);
      pts[3 * idx] = Q.x;
      pts[3 * idx + 1] = Q.y;
      pts[3 * idx + 2] = Q.z;
      wts[idx] = wp * ((k % 2 == 0) ? 1.0 : wm);
    }
  }
  std::vector<KnotVector> kvs = s.all_knots();
  kvs.push_back(kw);
  TensorSpline v(std::move(kvs), 3, std::move(pts), std::move(wts));
  if (params.angle_direction == 0) {
    const std::array<int, 3> order{2, 0, 1};
    v = permuted(v, order);
  } else if (params.angle_direction == 1) {
    const std::array<int, 3> order{0, 2, 1};
    v = permuted(v, order);
  }
  return detail::finish("revolve", std::move(v), params.check);
}

}  // namespace trivox
