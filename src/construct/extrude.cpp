// Extrusion and ruled volumes: two layers of control points, linear in w.
#include "trivox/construct/extrude.h"

#include "construct/construct_util.h"
#include "trivox/error.h"

namespace trivox {

Constructed extrude(const TensorSpline& surface, const ExtrudeParams& params) {
  const TensorSpline s = detail::checked_surface(surface, "extruded surface");
  const Vec3 d = params.vector_mm;
  detail::unit(d, "the extrusion vector");
  const TensorSpline top = s.transformed([d](std::span<double> p) {
    p[0] += d.x;
    p[1] += d.y;
    p[2] += d.z;
  });
  return detail::finish("extrude", detail::stack_layers({s, top}, KnotVector::bezier(2)), params.check);
}

Constructed ruled(const TensorSpline& from, const TensorSpline& to, const RuledParams& params) {
  TensorSpline a = detail::checked_surface(from, "first surface of the ruled volume");
  TensorSpline b = detail::checked_surface(to, "second surface of the ruled volume");
  // A polynomial surface next to a rational one becomes rational with unit weights.
  if (a.is_rational() != b.is_rational()) {
    TensorSpline& p = a.is_rational() ? b : a;
    p = TensorSpline(p.all_knots(), 3, std::vector<double>(p.points().begin(), p.points().end()),
                     std::vector<double>(static_cast<std::size_t>(p.total_ctrl()), 1.0));
  }
  for (int dir = 0; dir < 2; ++dir) detail::make_compatible({{&a, dir}, {&b, dir}});
  return detail::finish("ruled", detail::stack_layers({a, b}, KnotVector::bezier(2)), params.check);
}

}  // namespace trivox
