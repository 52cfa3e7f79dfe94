#include "trivox/spline/knot_vector.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "trivox/error.h"

namespace trivox {
namespace {

TEST(KnotVector, RejectsBrokenRules) {
  EXPECT_THROW(KnotVector(0, {0, 1}), ModelError);  // order < 1
  EXPECT_THROW(KnotVector(kMaxOrder + 1, std::vector<double>(70, 0.0)), ModelError);
  EXPECT_THROW(KnotVector(2, {0, 0, 1}), ModelError);                   // too few knots
  EXPECT_THROW(KnotVector(2, {0, 0, 0.5, 0.4, 1, 1}), ModelError);      // decreasing
  EXPECT_THROW(KnotVector(2, {0, 0, 0, 1, 1}), ModelError);             // multiplicity 3 > order 2
  EXPECT_THROW(KnotVector(2, {0, 0, std::nan(""), 1, 1}), ModelError);  // NaN
  EXPECT_THROW(KnotVector(2, {0, 0, 1, std::numeric_limits<double>::infinity()}), ModelError);
  EXPECT_THROW(KnotVector(2, {1, 1, 1, 1}), ModelError);  // empty domain
  try {
    KnotVector(3, {0, 0, 0, 0.7, 0.2, 1, 1, 1});
    FAIL();
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("decrease"), std::string::npos) << e.what();
  }
}

TEST(KnotVector, SpanSearchIsExactAtEndsAndRepeatedKnots) {
  const KnotVector kv(3, {0, 0, 0, 1, 2, 2, 3, 4, 4, 4});  // 7 basis functions, domain [0, 4]
  EXPECT_EQ(kv.num_basis(), 7);
  EXPECT_DOUBLE_EQ(kv.lo(), 0);
  EXPECT_DOUBLE_EQ(kv.hi(), 4);
  EXPECT_EQ(kv.find_span(0.0), 2);
  EXPECT_EQ(kv.find_span(-5.0), 2);  // clamped into the domain
  EXPECT_EQ(kv.find_span(0.5), 2);
  EXPECT_EQ(kv.find_span(1.0), 3);
  EXPECT_EQ(kv.find_span(2.0), 5);  // double knot: span starts at the last copy
  EXPECT_EQ(kv.find_span(1.999), 3);
  EXPECT_EQ(kv.find_span(4.0), 6);  // upper end: last non-empty span
  EXPECT_EQ(kv.find_span(7.0), 6);
  EXPECT_EQ(kv.multiplicity(2.0), 2);
  EXPECT_EQ(kv.interior_breaks(), (std::vector<double>{1, 2, 3}));
  EXPECT_TRUE(kv.is_clamped());
}

TEST(KnotVector, UnclampedDomainIsInnerKnots) {
  const KnotVector kv(4, {0, 1, 2, 3, 4, 5, 6, 7, 8});  // 5 basis functions, domain [3, 5]
  EXPECT_DOUBLE_EQ(kv.lo(), 3);
  EXPECT_DOUBLE_EQ(kv.hi(), 5);
  EXPECT_FALSE(kv.is_clamped());
  EXPECT_EQ(kv.find_span(5.0), 4);
  EXPECT_EQ(kv.find_span(3.0), 3);
}

TEST(KnotVector, PeriodicWrapsControlIndices) {
  // IRIT: n = 4 points, order 3 -> n + 2*order - 1 = 9 knots, 6 basis functions.
  const KnotVector kv = KnotVector::periodic(3, 4, {0, 1, 2, 3, 4, 5, 6, 7, 8});
  EXPECT_TRUE(kv.is_periodic());
  EXPECT_EQ(kv.num_basis(), 6);
  EXPECT_EQ(kv.num_ctrl(), 4);
  EXPECT_EQ(kv.ctrl_index(3), 3);
  EXPECT_EQ(kv.ctrl_index(4), 0);
  EXPECT_EQ(kv.ctrl_index(5), 1);
  EXPECT_DOUBLE_EQ(kv.lo(), 2);
  EXPECT_DOUBLE_EQ(kv.hi(), 6);
  EXPECT_THROW(KnotVector::periodic(3, 4, {0, 1, 2, 3, 4, 5, 6, 7}), ModelError);
}

TEST(KnotVector, UniformAndBezier) {
  const KnotVector u = KnotVector::clamped_uniform(3, 5);
  EXPECT_EQ(std::vector<double>(u.knots().begin(), u.knots().end()),
            (std::vector<double>{0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1}));
  const KnotVector b = KnotVector::bezier(4);
  EXPECT_EQ(b.num_basis(), 4);
  EXPECT_TRUE(b.interior_breaks().empty());
}

}  // namespace
}  // namespace trivox

namespace trivox {
namespace {

// The O(1) guess for uniform knots must agree with a plain linear scan everywhere,
// including exactly at knots and at values that round across them.
TEST(KnotVector, UniformSpanGuessAgreesWithLinearScan) {
  auto scan = [](const KnotVector& kv, double t) {
    t = std::clamp(t, kv.lo(), kv.hi());
    int s = kv.order() - 1;
    while (s < kv.num_basis() - 1 && kv[s + 1] <= t) ++s;
    return s;
  };
  for (int order : {1, 2, 3, 4, 7}) {
    for (int n : {order, order + 1, order + 9, order + 36}) {
      const KnotVector kv = KnotVector::clamped_uniform(order, n, -0.3, 1.7);
      for (int i = -5; i <= 1005; ++i) {
        const double t = -0.3 + 2.0 * i / 1000.0;
        EXPECT_EQ(kv.find_span(t), scan(kv, t)) << "order " << order << " n " << n << " t " << t;
        EXPECT_EQ(kv.find_span(std::nextafter(t, 10.0)), scan(kv, std::nextafter(t, 10.0)));
        EXPECT_EQ(kv.find_span(std::nextafter(t, -10.0)), scan(kv, std::nextafter(t, -10.0)));
      }
      for (double knot : kv.knots()) EXPECT_EQ(kv.find_span(knot), scan(kv, knot));
    }
  }
}

}  // namespace
}  // namespace trivox
