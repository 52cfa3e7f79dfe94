// Surfaces and curves for the constructor tests: exact rational discs and arcs, plates.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::test {

inline Vec3 eval3(const TensorSpline& s, std::array<double, 3> t) {
  double x[3];
  s.evaluate(std::span<const double>(t.data(), static_cast<std::size_t>(s.param_dim())), x);
  return {x[0], x[1], x[2]};
}

// A plate: bilinear over [x0, x1] x [y0, y1] in the plane given by mapping (a, b) -> point.
template <class Map>
TensorSpline bilinear_plate(Map map) {
  std::vector<double> pts;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const Vec3 p = map(static_cast<double>(i), static_cast<double>(j));
      pts.insert(pts.end(), {p.x, p.y, p.z});
    }
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2)}, 3, std::move(pts));
}

// An exact disc of radius r as a biquadratic rational 3x3 patch in the plane spanned by
// the unit vectors ex, ey around c: its boundary is the circle in four 90-degree arcs
// (corners on the circle at 45 degrees, edge midpoints at distance r sqrt 2, weight
// sqrt(2)/2; the centre weight 1/2).
inline TensorSpline rational_disc(Vec3 c, Vec3 ex, Vec3 ey, double r) {
  const double h = std::numbers::sqrt2 / 2;
  const double a[3] = {-1, 0, 1};
  const double wa[3] = {1, h, 1};
  std::vector<double> pts, w;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      double x = a[i], y = a[j];
      // Corners (x, y both +-1) are on the circle at 45 degrees; edge midpoints (one of them
      // 0) at distance r sqrt 2; the centre at c.
      double s = (i != 1 && j != 1) ? r * h : r * std::numbers::sqrt2;
      if (i == 1 && j == 1) s = 0;
      const Vec3 p = c + (s * x) * ex + (s * y) * ey;
      pts.insert(pts.end(), {p.x, p.y, p.z});
      w.push_back(wa[i] * wa[j]);
    }
  return TensorSpline({KnotVector::bezier(3), KnotVector::bezier(3)}, 3, std::move(pts), std::move(w));
}

// An exact full circle of radius r around c in the plane z = c.z: 9 points, 4 arcs.
inline TensorSpline circle_curve(Vec3 c, double r) {
  const double h = std::numbers::sqrt2 / 2;
  const double xy[9][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}, {1, 0}};
  std::vector<double> pts, w;
  for (int i = 0; i < 9; ++i) {
    pts.insert(pts.end(), {c.x + r * xy[i][0], c.y + r * xy[i][1], c.z});
    w.push_back(i % 2 ? h : 1.0);
  }
  return TensorSpline({KnotVector(3, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1})}, 3, std::move(pts),
                      std::move(w));
}

}  // namespace trivox::test
