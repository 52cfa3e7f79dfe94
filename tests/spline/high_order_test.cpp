// Curves, surfaces and trivariates of order 1 and of order 16 against references that share
// no code with the evaluators: Bezier pieces against Bernstein polynomials summed directly
// from binomial coefficients (rational ones as the quotient of two such sums), piecewise
// constant splines against their control points, and the linear precision of the basis
// (control points at the Greville abscissae reproduce the parameter). Both the general
// TensorSpline path and Volume's evaluator (de Boor beyond order 4) are checked.
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "trivox/spline/tensor_spline.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

// B_{i,n}(s), i = 0..n, with C(n, i) built by the multiplicative formula and the powers by
// repeated multiplication.
std::vector<double> bernstein(int n, double s) {
  std::vector<double> b(static_cast<std::size_t>(n + 1));
  double binomial = 1.0;
  for (int i = 0; i <= n; ++i) {
    double term = binomial;
    for (int q = 0; q < i; ++q) term *= s;
    for (int q = 0; q < n - i; ++q) term *= 1.0 - s;
    b[static_cast<std::size_t>(i)] = term;
    binomial = binomial * (n - i) / (i + 1);
  }
  return b;
}

// d/ds B_{i,n}(s) = n (B_{i-1,n-1}(s) - B_{i,n-1}(s)).
std::vector<double> bernstein_derivative(int n, double s) {
  std::vector<double> d(static_cast<std::size_t>(n + 1), 0.0);
  if (n == 0) return d;
  const std::vector<double> lower = bernstein(n - 1, s);
  for (int i = 0; i <= n; ++i) {
    const double left = i > 0 ? lower[static_cast<std::size_t>(i - 1)] : 0.0;
    const double right = i < n ? lower[static_cast<std::size_t>(i)] : 0.0;
    d[static_cast<std::size_t>(i)] = n * (left - right);
  }
  return d;
}

struct Reference {
  std::vector<double> value;     // point_dim values
  std::vector<double> partials;  // param_dim * point_dim, partials[d * point_dim + c]
};

// The Bezier spline `s` (no interior knots in any direction) at t as the sum over its
// control points of w P B_i(u) B_j(v) B_k(w), divided by the same sum without P; the
// partials by the quotient rule from the Bernstein derivatives, each scaled by 1 / (hi - lo).
Reference bernstein_reference(const TensorSpline& s, const std::vector<double>& t) {
  const int pd = s.param_dim(), dim = s.point_dim();
  std::vector<double> b[3], db[3];
  double scale[3] = {0, 0, 0};
  for (int d = 0; d < 3; ++d) {
    if (d >= pd) {
      b[d] = {1.0};
      db[d] = {0.0};
      continue;
    }
    const double lo = s.lo(d), hi = s.hi(d);
    const double local = (t[static_cast<std::size_t>(d)] - lo) / (hi - lo);
    b[d] = bernstein(s.knots(d).degree(), local);
    db[d] = bernstein_derivative(s.knots(d).degree(), local);
    scale[d] = 1.0 / (hi - lo);
  }
  std::vector<double> A(static_cast<std::size_t>(dim), 0.0), dA(static_cast<std::size_t>(3 * dim), 0.0);
  double W = 0.0, dW[3] = {0, 0, 0};
  for (int k = 0; k < s.num_ctrl(2); ++k)
    for (int j = 0; j < s.num_ctrl(1); ++j)
      for (int i = 0; i < s.num_ctrl(0); ++i) {
        const double w = s.weight(i, j, k);
        const double bi = b[0][static_cast<std::size_t>(i)], bj = b[1][static_cast<std::size_t>(j)],
                     bk = b[2][static_cast<std::size_t>(k)];
        const double basis = w * bi * bj * bk;
        const double dbasis[3] = {w * db[0][static_cast<std::size_t>(i)] * bj * bk * scale[0],
                                  w * bi * db[1][static_cast<std::size_t>(j)] * bk * scale[1],
                                  w * bi * bj * db[2][static_cast<std::size_t>(k)] * scale[2]};
        const auto p = s.point(i, j, k);
        W += basis;
        for (int d = 0; d < 3; ++d) dW[d] += dbasis[d];
        for (int c = 0; c < dim; ++c) {
          A[static_cast<std::size_t>(c)] += basis * p[static_cast<std::size_t>(c)];
          for (int d = 0; d < 3; ++d)
            dA[static_cast<std::size_t>(d * dim + c)] += dbasis[d] * p[static_cast<std::size_t>(c)];
        }
      }
  Reference r;
  r.value.resize(static_cast<std::size_t>(dim));
  r.partials.resize(static_cast<std::size_t>(pd * dim));
  for (int c = 0; c < dim; ++c) r.value[static_cast<std::size_t>(c)] = A[static_cast<std::size_t>(c)] / W;
  for (int d = 0; d < pd; ++d)
    for (int c = 0; c < dim; ++c)
      r.partials[static_cast<std::size_t>(d * dim + c)] =
          (dA[static_cast<std::size_t>(d * dim + c)] - r.value[static_cast<std::size_t>(c)] * dW[d]) / W;
  return r;
}

// A Bezier spline with the given orders on the given domains, random control points in
// [-1, 1]^dim and, when rational, random weights in [0.5, 2].
TensorSpline random_bezier(std::mt19937& rng, const std::vector<int>& orders, int dim, bool rational) {
  static constexpr double kLo[3] = {-1.0, 0.0, 2.0}, kHi[3] = {2.0, 1.0, 2.5};
  std::vector<KnotVector> knots;
  int n = 1;
  for (std::size_t d = 0; d < orders.size(); ++d) {
    knots.push_back(KnotVector::clamped_uniform(orders[d], orders[d], kLo[d], kHi[d]));
    n *= orders[d];
  }
  std::uniform_real_distribution<double> P(-1.0, 1.0), W(0.5, 2.0);
  std::vector<double> pts, w;
  for (int i = 0; i < n * dim; ++i) pts.push_back(P(rng));
  if (rational)
    for (int i = 0; i < n; ++i) w.push_back(W(rng));
  return TensorSpline(std::move(knots), dim, std::move(pts), std::move(w));
}

// Random parameters in the domain, and its corners.
std::vector<std::vector<double>> sample_params(const TensorSpline& s, std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::vector<double>> out;
  const int pd = s.param_dim();
  for (int corner = 0; corner < (1 << pd); ++corner) {
    std::vector<double> t;
    for (int d = 0; d < pd; ++d) t.push_back((corner >> d) & 1 ? s.hi(d) : s.lo(d));
    out.push_back(t);
  }
  for (int i = 0; i < count; ++i) {
    std::vector<double> t;
    for (int d = 0; d < pd; ++d) t.push_back(s.lo(d) + U(rng) * (s.hi(d) - s.lo(d)));
    out.push_back(t);
  }
  return out;
}

Vec3 as_vec3(const std::vector<double>& t) { return {t[0], t[1], t[2]}; }

// TensorSpline's value and partials (and Volume's, for a 3D trivariate) against the
// Bernstein reference at every sample.
void expect_matches_bernstein(const TensorSpline& s, std::mt19937& rng) {
  const int pd = s.param_dim(), dim = s.point_dim();
  std::vector<double> value(static_cast<std::size_t>(dim)), only(value.size()),
      partials(static_cast<std::size_t>(pd * dim));
  std::optional<Volume> volume;
  if (pd == 3 && dim == 3) {
    volume.emplace(s);
    const auto o = volume->orders();
    if (o[0] > 4 || o[1] > 4 || o[2] > 4 || o[0] < 2 || o[1] < 2 || o[2] < 2) {
      EXPECT_EQ(volume->kernel(), VolumeKernel::kDeBoor);
    }
  }
  for (const std::vector<double>& t : sample_params(s, rng, 200)) {
    const Reference ref = bernstein_reference(s, t);
    s.evaluate(t, only);
    s.evaluate_with_partials(t, value, partials);
    for (int c = 0; c < dim; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      EXPECT_NEAR(only[cc], ref.value[cc], 1e-12);
      EXPECT_NEAR(value[cc], ref.value[cc], 1e-12);
      for (int d = 0; d < pd; ++d) {
        const auto i = static_cast<std::size_t>(d * dim + c);
        EXPECT_NEAR(partials[i], ref.partials[i], 1e-10 * (1 + std::abs(ref.partials[i])));
      }
    }
    if (!volume) continue;
    const Vec3 q = volume->evaluate(as_vec3(t));
    Vec3 p;
    Mat3 J;
    volume->evaluate_jacobian(as_vec3(t), p, J);
    for (int c = 0; c < 3; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      EXPECT_NEAR(q[c], ref.value[cc], 1e-12);
      EXPECT_NEAR(p[c], ref.value[cc], 1e-12);
      for (int d = 0; d < 3; ++d) {
        const double r = ref.partials[static_cast<std::size_t>(d * 3 + c)];
        EXPECT_NEAR(J.m[cc][static_cast<std::size_t>(d)], r, 1e-10 * (1 + std::abs(r)));
      }
    }
  }
}

struct Shape {
  std::vector<int> orders;
  int point_dim;
};

// Curves, surfaces and trivariates; order 16 (degree 15) and order 1 in every direction,
// and mixed; point dimensions 1 to 5.
const Shape kShapes[] = {
    {{16}, 5},         {{1}, 2},       {{16, 16}, 3},   {{16, 16}, 1},     {{1, 1}, 3},
    {{16, 16, 16}, 3}, {{1, 1, 1}, 3}, {{16, 1, 3}, 3}, {{16, 16, 16}, 2},
};

TEST(HighOrder, PolynomialBezierMatchesBernsteinSums) {
  std::mt19937 rng(160);
  for (const Shape& shape : kShapes) {
    SCOPED_TRACE(::testing::Message() << shape.orders.size() << " directions, orders " << shape.orders[0]
                                      << ", point dimension " << shape.point_dim);
    expect_matches_bernstein(random_bezier(rng, shape.orders, shape.point_dim, false), rng);
  }
}

TEST(HighOrder, RationalBezierMatchesRationalBernsteinSums) {
  std::mt19937 rng(161);
  for (const Shape& shape : kShapes) {
    SCOPED_TRACE(::testing::Message() << shape.orders.size() << " directions, orders " << shape.orders[0]
                                      << ", point dimension " << shape.point_dim);
    const TensorSpline s = random_bezier(rng, shape.orders, shape.point_dim, true);
    // Varied weights: the rational spline is not the polynomial one with the same points.
    double spread = 0;
    for (double w : s.weights()) spread = std::max(spread, std::abs(w - s.weights()[0]));
    if (s.total_ctrl() > 1) {
      ASSERT_GT(spread, 0.1);
    }
    expect_matches_bernstein(s, rng);
  }
}

TEST(HighOrder, EqualWeightsGiveThePolynomialSpline) {
  std::mt19937 rng(162);
  for (const Shape& shape : kShapes) {
    const TensorSpline poly = random_bezier(rng, shape.orders, shape.point_dim, false);
    const TensorSpline rational(poly.all_knots(), poly.point_dim(),
                                std::vector<double>(poly.points().begin(), poly.points().end()),
                                std::vector<double>(static_cast<std::size_t>(poly.total_ctrl()), 2.75));
    ASSERT_TRUE(rational.is_rational());
    const int pd = poly.param_dim(), dim = poly.point_dim();
    std::vector<double> a(static_cast<std::size_t>(dim)), b(a.size()), da(static_cast<std::size_t>(pd * dim)),
        db(da.size());
    for (const std::vector<double>& t : sample_params(poly, rng, 100)) {
      poly.evaluate_with_partials(t, a, da);
      rational.evaluate_with_partials(t, b, db);
      for (std::size_t c = 0; c < a.size(); ++c) EXPECT_NEAR(a[c], b[c], 1e-13);
      for (std::size_t c = 0; c < da.size(); ++c) EXPECT_NEAR(da[c], db[c], 1e-11 * (1 + std::abs(da[c])));
    }
  }
}

// A clamped knot vector on [lo, hi] with interior knots at the given fractions of the
// domain (repeats allowed).
KnotVector clamped(int order, double lo, double hi, const std::vector<double>& interior) {
  std::vector<double> k(static_cast<std::size_t>(order), lo);
  for (double f : interior) k.push_back(lo + f * (hi - lo));
  k.insert(k.end(), static_cast<std::size_t>(order), hi);
  return KnotVector(order, k);
}

// Greville abscissae, the knot averages xi_i = (t_{i+1} + ... + t_{i+p}) / p.
std::vector<double> greville(const KnotVector& kv) {
  std::vector<double> xi;
  for (int i = 0; i < kv.num_ctrl(); ++i) {
    double sum = 0;
    for (int j = 1; j <= kv.degree(); ++j) sum += kv[i + j];
    xi.push_back(sum / kv.degree());
  }
  return xi;
}

// The spline sum_i xi_i N_i(t) with xi the Greville abscissae is t itself (linear
// precision, orders 2 and up). Built per direction in the coordinate of that direction: a curve gives t, a
// surface (u, v), a trivariate (u, v, w), and the derivative is the identity.
TensorSpline greville_identity(const std::vector<KnotVector>& knots, double weight) {
  std::vector<std::vector<double>> xi;
  for (const KnotVector& kv : knots) xi.push_back(greville(kv));
  const int pd = static_cast<int>(knots.size());
  const int n0 = knots[0].num_ctrl(), n1 = pd > 1 ? knots[1].num_ctrl() : 1, n2 = pd > 2 ? knots[2].num_ctrl() : 1;
  std::vector<double> pts, w;
  for (int k = 0; k < n2; ++k)
    for (int j = 0; j < n1; ++j)
      for (int i = 0; i < n0; ++i) {
        const int index[3] = {i, j, k};
        for (int d = 0; d < pd; ++d) pts.push_back(xi[static_cast<std::size_t>(d)][static_cast<std::size_t>(index[d])]);
        if (weight > 0) w.push_back(weight);
      }
  return TensorSpline(knots, pd, std::move(pts), std::move(w));
}

TEST(HighOrder, GrevilleControlPointsReproduceTheParameter) {
  // Order 16 with several pieces, uneven spacing and a knot of multiplicity 3; and a mix of
  // orders 16, 2 and 7.
  const KnotVector k16a = clamped(16, -1.0, 3.0, {0.1, 0.45, 0.45, 0.45, 0.8});
  const KnotVector k16b = clamped(16, 0.0, 1.0, {0.3, 0.35});
  const KnotVector k2 = clamped(2, 5.0, 6.0, {0.2, 0.7});
  const KnotVector k7 = clamped(7, 0.0, 0.5, {0.5, 0.5});
  const std::vector<std::vector<KnotVector>> cases = {
      {k16a}, {k16a, k16b}, {k16a, k16b, k16a}, {k16b, k2, k7}, {k7, k16a, k2}};
  std::mt19937 rng(163);
  for (const std::vector<KnotVector>& knots : cases)
    for (double weight : {0.0, 3.7}) {  // polynomial, then rational with equal weights
      const TensorSpline s = greville_identity(knots, weight);
      const int pd = s.param_dim();
      SCOPED_TRACE(::testing::Message() << pd << " directions, weight " << weight);
      std::vector<double> value(static_cast<std::size_t>(pd)), partials(static_cast<std::size_t>(pd * pd));
      std::optional<Volume> volume;
      if (pd == 3) {
        volume.emplace(s);
        EXPECT_EQ(volume->kernel(), VolumeKernel::kDeBoor);
      }
      std::vector<std::vector<double>> params = sample_params(s, rng, 300);
      for (int d = 0; d < pd; ++d)  // every knot, in each direction in turn
        for (double knot : s.knots(d).knots()) {
          std::vector<double> t = params.back();
          t[static_cast<std::size_t>(d)] = knot;
          params.push_back(t);
        }
      for (const std::vector<double>& t : params) {
        s.evaluate_with_partials(t, value, partials);
        for (int d = 0; d < pd; ++d) {
          const double scale = std::max(std::abs(s.lo(d)), std::abs(s.hi(d)));
          EXPECT_NEAR(value[static_cast<std::size_t>(d)], t[static_cast<std::size_t>(d)], 1e-13 * scale);
          for (int c = 0; c < pd; ++c)
            EXPECT_NEAR(partials[static_cast<std::size_t>(d * pd + c)], d == c ? 1.0 : 0.0, 1e-10);
        }
        if (!volume) continue;
        Vec3 p;
        Mat3 J;
        volume->evaluate_jacobian(as_vec3(t), p, J);
        const Vec3 q = volume->evaluate(as_vec3(t));
        for (int d = 0; d < 3; ++d) {
          const double scale = std::max(std::abs(s.lo(d)), std::abs(s.hi(d)));
          EXPECT_NEAR(p[d], t[static_cast<std::size_t>(d)], 1e-13 * scale);
          EXPECT_NEAR(q[d], t[static_cast<std::size_t>(d)], 1e-13 * scale);
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(J.m[static_cast<std::size_t>(d)][static_cast<std::size_t>(c)], d == c ? 1.0 : 0.0, 1e-10);
        }
      }
    }
}

// Order 1: N_i is 1 on [t_i, t_{i+1}) (the last span closed at the top), so the spline
// takes the value of one control point per span, whatever the weights.
TEST(HighOrder, OrderOneIsPiecewiseConstant) {
  const std::vector<double> breaks_u = {0.0, 0.2, 0.5, 0.9, 1.0}, breaks_v = {-2.0, 1.0, 4.0},
                            breaks_w = {3.0, 3.1, 3.3, 3.6, 4.0, 4.5};
  const std::vector<KnotVector> knots = {KnotVector(1, breaks_u), KnotVector(1, breaks_v), KnotVector(1, breaks_w)};
  std::mt19937 rng(164);
  std::uniform_real_distribution<double> P(-10.0, 10.0), W(0.5, 2.0), U(0.0, 1.0);
  const auto span_of = [](const std::vector<double>& breaks, double t) {
    int s = 0;
    while (s + 2 < static_cast<int>(breaks.size()) && t >= breaks[static_cast<std::size_t>(s + 1)]) ++s;
    return s;
  };
  const std::vector<double>* breaks[3] = {&breaks_u, &breaks_v, &breaks_w};
  for (std::size_t pd = 1; pd <= 3; ++pd)
    for (bool rational : {false, true}) {
      const std::vector<KnotVector> kv(knots.begin(), knots.begin() + static_cast<std::ptrdiff_t>(pd));
      int n = 1;
      for (const KnotVector& k : kv) n *= k.num_ctrl();
      std::vector<double> pts, w;
      for (int i = 0; i < 3 * n; ++i) pts.push_back(P(rng));
      if (rational)
        for (int i = 0; i < n; ++i) w.push_back(W(rng));
      const TensorSpline s(kv, 3, pts, w);
      std::optional<Volume> volume;
      if (pd == 3) volume.emplace(s);
      std::vector<std::vector<double>> params = sample_params(s, rng, 200);
      for (std::size_t d = 0; d < pd; ++d)  // every break, where the value jumps
        for (double b : *breaks[d]) {
          std::vector<double> t = params.back();
          t[d] = b;
          params.push_back(t);
        }
      std::vector<double> value(3), partials(3 * pd);
      for (const std::vector<double>& t : params) {
        int idx[3] = {0, 0, 0};
        for (std::size_t d = 0; d < pd; ++d) idx[d] = span_of(*breaks[d], t[d]);
        const auto expected = s.point(idx[0], idx[1], idx[2]);
        s.evaluate_with_partials(t, value, partials);
        for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(value[c], expected[c], 1e-13);
        for (double partial : partials) EXPECT_EQ(partial, 0.0);
        if (!volume) continue;
        Vec3 p;
        Mat3 J;
        volume->evaluate_jacobian(as_vec3(t), p, J);
        const Vec3 q = volume->evaluate(as_vec3(t));
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(p[c], expected[static_cast<std::size_t>(c)], 1e-13);
          EXPECT_NEAR(q[c], expected[static_cast<std::size_t>(c)], 1e-13);
          for (int d = 0; d < 3; ++d) EXPECT_EQ(J.m[static_cast<std::size_t>(c)][static_cast<std::size_t>(d)], 0.0);
        }
      }
    }
}

}  // namespace
}  // namespace trivox
