// The calibration curve of greyscale layers (raster/greyscale.h): the grey of a value is the
// straight line between the neighbouring calibration points, exact at the points, held beyond
// the ends, rounded to the nearest level; curves that are not monotone or not functions of the
// value are refused.
#include "trivox/raster/greyscale.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "trivox/error.h"

namespace trivox {
namespace {

// The line through (a, ga) and (b, gb) at v, in long double: an independent evaluation.
long double line(long double a, long double ga, long double b, long double gb, long double v) {
  return ga + (v - a) * (gb - ga) / (b - a);
}

TEST(GreyCalibration, ExactAtThePointsLinearBetweenHeldBeyond) {
  const GreyCalibration c({{0.0, 40.0}, {0.25, 90.0}, {0.6, 200.0}, {1.0, 255.0}});
  EXPECT_EQ(c.grey(0.0), 40.0);
  EXPECT_EQ(c.grey(0.25), 90.0);
  EXPECT_EQ(c.grey(0.6), 200.0);
  EXPECT_EQ(c.grey(1.0), 255.0);
  EXPECT_EQ(c.grey(-3.0), 40.0);
  EXPECT_EQ(c.grey(7.0), 255.0);
  EXPECT_EQ(c.grey(std::numeric_limits<double>::quiet_NaN()), 40.0);
  EXPECT_EQ(c.grey(-std::numeric_limits<double>::infinity()), 40.0);
  EXPECT_EQ(c.grey(std::numeric_limits<double>::infinity()), 255.0);
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    long double expected;
    if (v <= 0.25)
      expected = line(0.0L, 40.0L, 0.25L, 90.0L, v);
    else if (v <= 0.6)
      expected = line(0.25L, 90.0L, 0.6L, 200.0L, v);
    else
      expected = line(0.6L, 200.0L, 1.0L, 255.0L, v);
    EXPECT_NEAR(c.grey(v), static_cast<double>(expected), 1e-12) << v;
    // The level is the nearest integer, halves up.
    EXPECT_EQ(c.level(v), static_cast<int>(std::floor(static_cast<double>(expected) + 0.5))) << v;
  }
}

TEST(GreyCalibration, FallingCurvesAndFlatStretchesAreMonotone) {
  const GreyCalibration falling({{0.0, 255.0}, {0.5, 255.0}, {1.0, 0.0}});
  EXPECT_EQ(falling.grey(0.25), 255.0);
  EXPECT_EQ(falling.grey(0.75), 127.5);
  EXPECT_EQ(falling.level(0.75), 128);  // a half rounds up
  const GreyCalibration one({{3.0, 17.0}});
  EXPECT_EQ(one.grey(-1.0), 17.0);
  EXPECT_EQ(one.grey(99.0), 17.0);
  EXPECT_EQ(GreyCalibration().level(0.3), 255);  // the default exposes fully
}

TEST(GreyCalibration, RoundLevelClampsAndRoundsHalvesUp) {
  EXPECT_EQ(GreyCalibration::round_level(-4.0), 0);
  EXPECT_EQ(GreyCalibration::round_level(0.49), 0);
  EXPECT_EQ(GreyCalibration::round_level(0.5), 1);
  EXPECT_EQ(GreyCalibration::round_level(254.5), 255);
  EXPECT_EQ(GreyCalibration::round_level(300.0), 255);
}

TEST(GreyCalibration, RefusesCurvesThatAreNotMonotoneFunctions) {
  auto message = [](std::vector<GreyPoint> points) -> std::string {
    try {
      GreyCalibration c(std::move(points));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({}).find("at least one"), std::string::npos);
  EXPECT_NE(message({{0, 10}, {0.5, 200}, {1, 100}}).find("monotone"), std::string::npos);
  EXPECT_NE(message({{0, 200}, {0.5, 100}, {0.7, 100}, {1, 150}}).find("monotone"), std::string::npos);
  EXPECT_NE(message({{0, 10}, {0, 20}}).find("increase"), std::string::npos);
  EXPECT_NE(message({{1, 10}, {0.5, 20}}).find("increase"), std::string::npos);
  EXPECT_NE(message({{0, -1}}).find("[0, 255]"), std::string::npos);
  EXPECT_NE(message({{0, 256}}).find("[0, 255]"), std::string::npos);
  EXPECT_NE(message({{std::numeric_limits<double>::quiet_NaN(), 5}}).find("finite"), std::string::npos);
  EXPECT_EQ(message({{0, 10}, {0.5, 10}, {1, 250}}), "");
}

}  // namespace
}  // namespace trivox
