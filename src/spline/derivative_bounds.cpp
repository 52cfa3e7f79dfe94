#include "derivative_bounds.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace trivox::detail {

namespace {

// A net of 3D points over the basis indices of three directions, u fastest; `knots` are the
// knot vectors the net's basis lives on (shortened by one at each end per derivative taken).
struct Net {
  std::array<int, 3> n{};
  std::array<std::vector<double>, 3> knots;
  std::array<int, 3> degree{};
  std::vector<Vec3> p;

  Vec3& at(int i, int j, int k) { return p[static_cast<std::size_t>(i + n[0] * (j + n[1] * k))]; }
  const Vec3& at(int i, int j, int k) const { return p[static_cast<std::size_t>(i + n[0] * (j + n[1] * k))]; }
};

// The control net of dV/dt_dir: Q_i = p (P_{i+1} - P_i) / (t_{i+p+1} - t_{i+1}). A zero
// denominator belongs to a basis function that vanishes identically; its point is set to 0.
Net differentiate(const Net& a, int dir) {
  Net b = a;
  const int p = a.degree[static_cast<std::size_t>(dir)];
  if (p == 0) {  // piecewise constant along dir: the derivative is zero
    std::fill(b.p.begin(), b.p.end(), Vec3{});
    return b;
  }
  b.n[static_cast<std::size_t>(dir)] -= 1;
  b.degree[static_cast<std::size_t>(dir)] = p - 1;
  const std::vector<double>& t = a.knots[static_cast<std::size_t>(dir)];
  b.knots[static_cast<std::size_t>(dir)] = std::vector<double>(t.begin() + 1, t.end() - 1);
  b.p.assign(static_cast<std::size_t>(b.n[0] * b.n[1] * b.n[2]), Vec3{});
  for (int k = 0; k < b.n[2]; ++k)
    for (int j = 0; j < b.n[1]; ++j)
      for (int i = 0; i < b.n[0]; ++i) {
        std::array<int, 3> lo{i, j, k}, hi{i, j, k};
        hi[static_cast<std::size_t>(dir)] += 1;
        const int m = lo[static_cast<std::size_t>(dir)];
        const double span = t[static_cast<std::size_t>(m + p + 1)] - t[static_cast<std::size_t>(m + 1)];
        if (!(span > 0)) continue;
        b.at(i, j, k) = (static_cast<double>(p) / span) * (a.at(hi[0], hi[1], hi[2]) - a.at(lo[0], lo[1], lo[2]));
      }
  return b;
}

double max_norm(const Net& a) {
  double m = 0;
  for (const Vec3& q : a.p) m = std::max(m, norm(q));
  return m;
}

}  // namespace

std::optional<Mat3> second_derivative_bounds(const TensorSpline& spline) {
  if (spline.is_rational() || spline.param_dim() != 3 || spline.point_dim() != 3) return std::nullopt;
  Net net;
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline.knots(d);
    net.n[static_cast<std::size_t>(d)] = kv.num_basis();
    net.knots[static_cast<std::size_t>(d)].assign(kv.knots().begin(), kv.knots().end());
    net.degree[static_cast<std::size_t>(d)] = kv.degree();
  }
  net.p.resize(static_cast<std::size_t>(net.n[0] * net.n[1] * net.n[2]));
  for (int k = 0; k < net.n[2]; ++k)
    for (int j = 0; j < net.n[1]; ++j)
      for (int i = 0; i < net.n[0]; ++i) {
        const auto q =
            spline.point(spline.knots(0).ctrl_index(i), spline.knots(1).ctrl_index(j), spline.knots(2).ctrl_index(k));
        net.at(i, j, k) = {q[0], q[1], q[2]};
      }
  Mat3 bound;
  for (int a = 0; a < 3; ++a) {
    const Net first = differentiate(net, a);
    for (int b = a; b < 3; ++b) {
      const double m = max_norm(differentiate(first, b));
      if (!std::isfinite(m)) return std::nullopt;
      bound.m[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)] = m;
      bound.m[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)] = m;
    }
  }
  return bound;
}

}  // namespace trivox::detail
