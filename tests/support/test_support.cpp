#include "support/test_support.h"

#include <cmath>
#include <numbers>
#include <vector>

namespace trivox::test {

std::filesystem::path shared_data_dir() {
  const std::filesystem::path p = TRIVOX_SHARED_DATA_DIR;
  std::error_code ec;
  return std::filesystem::is_directory(p, ec) ? p : std::filesystem::path{};
}

std::string shared_data_missing_message() {
  return std::string("skipped: ../shared/data (the real models beside the repository) is absent at ") +
         TRIVOX_SHARED_DATA_DIR;
}

namespace {
// Exact rational quadratic quarter circle of radius r in the xy-plane: 3 points, weights
// 1, sqrt(2)/2, 1 (The NURBS Book, Section 7.5).
void quarter_circle(double r, double z, std::vector<double>& pts, std::vector<double>& w) {
  const double h = std::numbers::sqrt2 / 2;
  const double xy[3][2] = {{r, 0}, {r, r}, {0, r}};
  const double ws[3] = {1, h, 1};
  for (int i = 0; i < 3; ++i) {
    pts.insert(pts.end(), {xy[i][0], xy[i][1], z});
    w.push_back(ws[i]);
  }
}
}  // namespace

Volume annulus_sector(double r0, double r1, double h) {
  // u: radius (2 points), v: angle (3 points, rational), w: height (2 points); u fastest.
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) {
        std::vector<double> cp, cw;
        quarter_circle(i == 0 ? r0 : r1, k * h, cp, cw);
        pts.insert(pts.end(), {cp[static_cast<std::size_t>(3 * j)], cp[static_cast<std::size_t>(3 * j + 1)],
                               cp[static_cast<std::size_t>(3 * j + 2)]});
        w.push_back(cw[static_cast<std::size_t>(j)]);
      }
  return Volume(TensorSpline({KnotVector::bezier(2), KnotVector::bezier(3), KnotVector::bezier(2)}, 3, std::move(pts),
                             std::move(w)));
}

Volume cylinder_sector(double r, double h) { return annulus_sector(0.0, r, h); }

namespace {
// Control points at the Greville abscissae of a clamped basis reproduce the identity map
// (the span midpoints stand in for order 1).
std::vector<double> greville_points(const KnotVector& kv) {
  const int ctrl = kv.num_ctrl(), order = kv.order();
  std::vector<double> g(static_cast<std::size_t>(ctrl));
  for (int i = 0; i < ctrl; ++i) {
    double s = 0;
    for (int j = 1; j < order; ++j) s += kv[i + j];
    g[static_cast<std::size_t>(i)] = order > 1 ? s / (order - 1) : (i + 0.5) / ctrl;
  }
  return g;
}
}  // namespace

Volume twisted_bent_volume(const KnotVector& ku, const KnotVector& kv, const KnotVector& kw, Vec3 size, double twist,
                           double bend) {
  // The identity map, then a twist about the z axis and a bend along x deform it smoothly.
  const std::vector<double> gu = greville_points(ku), gv = greville_points(kv), gw = greville_points(kw);
  const double sx = size.x, sy = size.y, sz = size.z;
  std::vector<double> pts;
  for (double t : gw)
    for (double v : gv)
      for (double u : gu) {
        const double angle = twist * t;  // radians over the height
        // Rows bow in the plane of each layer too (a parabola in v), so that no layer is an
        // affine image of the parameter plane.
        const double x0 = (u - 0.5) * sx + 0.08 * sx * (v - 0.5) * (v - 0.5), y0 = (v - 0.5) * sy;
        const double x = std::cos(angle) * x0 - std::sin(angle) * y0;
        const double y = std::sin(angle) * x0 + std::cos(angle) * y0;
        const double shift = bend * sx * (t - 0.5) * (t - 0.5);  // bend the column along x
        pts.insert(pts.end(), {x + shift + 0.5 * sx, y + 0.5 * sy, t * sz});
      }
  return Volume(TensorSpline({ku, kv, kw}, 3, std::move(pts)));
}

Volume twisted_bent_box(double sx, double sy, double sz, int ctrl, int order) {
  const KnotVector kv = KnotVector::clamped_uniform(order, ctrl);
  return twisted_bent_volume(kv, kv, kv, {sx, sy, sz}, 0.35, 0.15);
}

TensorSpline random_rational_spline(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0), W(0.5, 2.0);
  const KnotVector ku(3, {0, 0.5, 1, 2, 3, 3.5, 4, 5});
  const KnotVector kv = KnotVector::periodic(4, 5, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11});
  const KnotVector kw(2, {0, 0, 0.3, 1, 1});
  const int n = ku.num_ctrl() * kv.num_ctrl() * kw.num_ctrl();
  std::vector<double> pts, w;
  for (int i = 0; i < n; ++i) {
    pts.insert(pts.end(), {U(rng), U(rng), U(rng)});
    w.push_back(W(rng));
  }
  return TensorSpline({ku, kv, kw}, 3, pts, w);
}

}  // namespace trivox::test
