#include "trivox/spline/detail/basis.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace trivox {
namespace {

// A random clamped knot vector of the given order with some repeated interior knots.
KnotVector random_knots(std::mt19937& rng, int order, int pieces) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<double> interior;
  for (int i = 0; i < pieces - 1; ++i) interior.push_back(U(rng));
  std::sort(interior.begin(), interior.end());
  if (pieces > 2 && order > 1) interior.push_back(interior[0]);  // one double knot
  std::sort(interior.begin(), interior.end());
  std::vector<double> knots(static_cast<std::size_t>(order), 0.0);
  knots.insert(knots.end(), interior.begin(), interior.end());
  knots.insert(knots.end(), static_cast<std::size_t>(order), 1.0);
  return KnotVector(order, knots);
}

class BasisProperties : public ::testing::TestWithParam<int> {};

TEST_P(BasisProperties, PartitionOfUnityNonNegativityAndDerivatives) {
  const int order = GetParam();
  std::mt19937 rng(1234u + static_cast<unsigned>(order));
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const KnotVector kv = random_knots(rng, order, 5);
    const int k = kv.order();
    std::vector<double> N(static_cast<std::size_t>(k)), D(static_cast<std::size_t>(3 * k));
    for (int s = 0; s < 50; ++s) {
      const double t = s == 0 ? 0.0 : (s == 1 ? 1.0 : U(rng));
      const int span = kv.find_span(t);
      basis_functions(kv, span, t, N.data());
      double sum = 0;
      for (double n : N) {
        EXPECT_GE(n, -1e-15);
        sum += n;
      }
      EXPECT_NEAR(sum, 1.0, 1e-13);
      basis_derivatives(kv, span, t, 2, D.data());
      for (int j = 0; j < k; ++j) EXPECT_NEAR(D[static_cast<std::size_t>(j)], N[static_cast<std::size_t>(j)], 1e-13);
      double dsum = 0;
      for (int j = 0; j < k; ++j) dsum += D[static_cast<std::size_t>(k + j)];
      EXPECT_NEAR(dsum, 0.0, 1e-8 * (1 + order * order));  // derivative of a constant

      // Central differences inside the span (away from its ends, where the basis is smooth).
      const double a = kv[span], b = kv[span + 1];
      const double h = 1e-6 * (b - a);
      if (t - a < 10 * h || b - t < 10 * h) continue;
      std::vector<double> Np(static_cast<std::size_t>(k)), Nm(static_cast<std::size_t>(k));
      basis_functions(kv, span, t + h, Np.data());
      basis_functions(kv, span, t - h, Nm.data());
      for (int j = 0; j < k; ++j) {
        const double fd = (Np[static_cast<std::size_t>(j)] - Nm[static_cast<std::size_t>(j)]) / (2 * h);
        const double exact = D[static_cast<std::size_t>(k + j)];
        EXPECT_NEAR(fd, exact, 1e-5 * (1 + std::abs(exact))) << "order " << order << " t " << t;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Orders, BasisProperties, ::testing::Values(1, 2, 3, 4, 5, 8, 12, 16));

TEST(Basis, LinearBasisIsHatFunction) {
  const KnotVector kv(2, {0, 0, 0.5, 1, 1});
  double N[2];
  const int span = kv.find_span(0.25);
  basis_functions(kv, span, 0.25, N);
  EXPECT_DOUBLE_EQ(N[0], 0.5);
  EXPECT_DOUBLE_EQ(N[1], 0.5);
}

TEST(Basis, CubicBezierIsBernstein) {
  const KnotVector kv = KnotVector::bezier(4);
  double D[8];
  const double t = 0.3;
  basis_derivatives(kv, kv.find_span(t), t, 1, D);
  const double s = 1 - t;
  EXPECT_NEAR(D[0], s * s * s, 1e-15);
  EXPECT_NEAR(D[1], 3 * t * s * s, 1e-15);
  EXPECT_NEAR(D[2], 3 * t * t * s, 1e-15);
  EXPECT_NEAR(D[3], t * t * t, 1e-15);
  EXPECT_NEAR(D[4], -3 * s * s, 1e-14);
  EXPECT_NEAR(D[7], 3 * t * t, 1e-14);
}

TEST(Basis, FirstDerivativeFastPathMatchesA23) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int order : {1, 2, 3, 4, 6, 9, 16, 20}) {
    const KnotVector kv = random_knots(rng, order, 6);
    std::vector<double> v(static_cast<std::size_t>(order)), d(static_cast<std::size_t>(order)),
        ref(static_cast<std::size_t>(2 * order));
    for (int s = 0; s < 200; ++s) {
      const double t = s == 0 ? 0.0 : (s == 1 ? 1.0 : U(rng));
      const int span = kv.find_span(t);
      basis_first_derivatives(kv, span, t, v.data(), d.data());
      basis_derivatives(kv, span, t, 1, ref.data());
      for (int j = 0; j < order; ++j) {
        EXPECT_NEAR(v[static_cast<std::size_t>(j)], ref[static_cast<std::size_t>(j)], 1e-13);
        EXPECT_NEAR(d[static_cast<std::size_t>(j)], ref[static_cast<std::size_t>(order + j)],
                    1e-9 * (1 + std::abs(ref[static_cast<std::size_t>(order + j)])));
      }
    }
  }
}

}  // namespace
}  // namespace trivox
