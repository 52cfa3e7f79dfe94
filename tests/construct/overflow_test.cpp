// Numbers beyond double range are said to overflow where they are first known, never passed
// on as a shape: a shell thickness of 1e308 is refused by the constructor, and a volume whose
// det J is infinite or undefined by the Jacobian check, instead of "degenerate: det J = 0".
#include <string>

#include <gtest/gtest.h>

#include "construct/construct_fixtures.h"
#include "scene/scene_test_util.h"
#include "trivox/construct/report.h"
#include "trivox/construct/shell.h"
#include "trivox/error.h"
#include "trivox/spline/jacobian_check.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

template <class F>
std::string model_error_of(F f) {
  return test::error_of<ModelError>(f);
}

TEST(Overflow, AShellThicknessBeyondDoubleRangeIsRefusedAsOverflowing) {
  const TensorSpline plate = test::bilinear_plate([](double a, double b) { return Vec3{10 * a, 10 * b, 0}; });
  ShellParams p;
  p.thickness_mm = 1e308;
  EXPECT_NE(model_error_of([&] { thick_shell(plate, p); }).find("overflows"), std::string::npos);
  p.thickness_mm = 5;
  EXPECT_NO_THROW(thick_shell(plate, p));
}

// A trilinear volume with a corner at 1e200: its coordinates are finite, det J (a product of
// three edge lengths) is not.
TEST(Overflow, AnInfiniteDetJIsAnOverflowNotADegenerateVolume) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const double s = i + j + k == 3 ? 1e200 : 1.0;
        pts.insert(pts.end(), {s * i, s * j, s * k});
      }
  const KnotVector k = KnotVector::bezier(2);
  const Volume v(TensorSpline({k, k, k}, 3, std::move(pts)));
  const std::string what = model_error_of([&] { check_jacobian(v); });
  EXPECT_NE(what.find("the volume's numbers overflow"), std::string::npos) << what;
  EXPECT_NE(model_error_of([&] { inspect_volume(v, {}); }).find("overflow"), std::string::npos);
}

}  // namespace
}  // namespace trivox
