#include "construct/construct_util.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/spline/refine.h"
#include "trivox/spline/respace.h"

namespace trivox::detail {

TensorSpline checked_surface(const TensorSpline& s, const std::string& role) {
  if (s.param_dim() != 2)
    throw ModelError(fmt::format("the {} must be a surface (2 parameters), not a spline of {}", role, s.param_dim()));
  if (s.point_dim() != 3)
    throw ModelError(fmt::format("the {} must have 3D control points, not {} coordinate(s)", role, s.point_dim()));
  return clamped(s);
}

void make_compatible(const std::vector<SplineDir>& group, int min_order) {
  int order = min_order;
  for (SplineDir g : group) {
    *g.spline = reparametrized(clamped(*g.spline), g.dir, 0.0, 1.0);
    order = std::max(order, g.spline->knots(g.dir).order());
  }
  // Multiplicity each interior knot needs so that every member's space fits in.
  std::map<double, int> mult;
  for (SplineDir g : group) {
    const KnotVector& kv = g.spline->knots(g.dir);
    const int raise = order - kv.order();
    for (double b : kv.interior_breaks()) mult[b] = std::max(mult[b], kv.multiplicity(b) + raise);
  }
  std::vector<double> knots(static_cast<std::size_t>(order), 0.0);
  for (const auto& [b, m] : mult) knots.insert(knots.end(), static_cast<std::size_t>(std::min(m, order)), b);
  knots.insert(knots.end(), static_cast<std::size_t>(order), 1.0);
  const KnotVector target(order, std::move(knots));
  for (SplineDir g : group) *g.spline = respace(*g.spline, g.dir, target);
}

TensorSpline stack_layers(const std::vector<TensorSpline>& layers, const KnotVector& w_knots) {
  const TensorSpline& first = layers.front();
  if (static_cast<int>(layers.size()) != w_knots.num_ctrl())
    throw ModelError(fmt::format("{} layers for {} control points along w", layers.size(), w_knots.num_ctrl()));
  std::vector<double> pts, w;
  for (const TensorSpline& l : layers) {
    if (l.all_knots() != first.all_knots() || l.is_rational() != first.is_rational() || l.point_dim() != 3)
      throw ModelError("the layers of a volume must share their knot vectors");
    pts.insert(pts.end(), l.points().begin(), l.points().end());
    w.insert(w.end(), l.weights().begin(), l.weights().end());
  }
  std::vector<KnotVector> knots = first.all_knots();
  knots.push_back(w_knots);
  return TensorSpline(std::move(knots), 3, std::move(pts), std::move(w));
}

Constructed finish(const std::string& constructor, TensorSpline spline, const JacobianCheckParams& check, bool exact,
                   double approximation_error_mm) {
  Volume volume(std::move(spline));
  ConstructionReport report = inspect_volume(volume, check);
  report.constructor = constructor;
  report.exact = exact;
  report.approximation_error_mm = approximation_error_mm;
  return Constructed{std::move(volume), std::move(report)};
}

Vec3 unit(Vec3 v, const std::string& what) {
  const double n = norm(v);
  if (!(n > 0.0) || !std::isfinite(n)) throw ModelError(fmt::format("{} is zero or not finite", what));
  return (1.0 / n) * v;
}

}  // namespace trivox::detail
