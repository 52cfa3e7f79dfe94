// Joining a grid of surfaces into one (construct/join.h): the joined surface is each patch
// on its own part of the domain, exactly, whatever the patches' orders and knots; patches
// that do not meet are named.
#include <array>
#include <vector>

#include <gtest/gtest.h>

#include "construct/construct_fixtures.h"
#include "trivox/construct/join.h"
#include "trivox/error.h"

namespace trivox {
namespace {

using test::eval3;

// A patch over [x0, x0 + 1] x [y0, y0 + 1] (u along x, v along y) of the height field
// z = f(x, y): control points on f at evenly spaced parameters, so that two patches with
// the same order along a shared edge have the same control points there.
TensorSpline height_patch(double x0, double y0, int ou, int ov) {
  std::vector<double> pts;
  for (int j = 0; j < ov; ++j)
    for (int i = 0; i < ou; ++i) {
      const double x = x0 + static_cast<double>(i) / (ou - 1), y = y0 + static_cast<double>(j) / (ov - 1);
      pts.insert(pts.end(), {x, y, x * x - 0.5 * x * y + y});  // shared edges: same values
    }
  return TensorSpline({KnotVector::bezier(ou), KnotVector::bezier(ov)}, 3, std::move(pts));
}

TEST(Join, GridOfPatchesOfMixedOrdersIsEachPatchExactly) {
  // Edge control points agree only where the orders along the edge agree, so each column
  // has one u order and each row one v order; the joined surface raises them all.
  std::vector<std::vector<TensorSpline>> grid = {
      {height_patch(0, 0, 2, 3), height_patch(1, 0, 4, 3), height_patch(2, 0, 3, 3)},
      {height_patch(0, 1, 2, 2), height_patch(1, 1, 4, 2), height_patch(2, 1, 3, 2)}};
  const TensorSpline joined = join_surfaces(grid);
  EXPECT_EQ(joined.param_dim(), 2);
  EXPECT_DOUBLE_EQ(joined.lo(0), 0.0);
  EXPECT_DOUBLE_EQ(joined.hi(0), 3.0);
  EXPECT_DOUBLE_EQ(joined.hi(1), 2.0);
  EXPECT_EQ(joined.knots(0).order(), 4);
  EXPECT_EQ(joined.knots(1).order(), 3);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c)
      for (double a : {0.0, 0.3, 0.77, 1.0})
        for (double b : {0.0, 0.45, 1.0}) {
          const Vec3 want = eval3(grid[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)], {a, b, 0});
          const Vec3 got = eval3(joined, {c + a, r + b, 0});
          EXPECT_NEAR(norm(got - want), 0.0, 1e-12) << "patch " << r << "," << c << " at " << a << "," << b;
        }
}

TEST(Join, PatchesThatDoNotMeetAreNamed) {
  std::vector<std::vector<TensorSpline>> grid = {{height_patch(0, 0, 3, 3), height_patch(1.5, 0, 3, 3)}};
  try {
    join_surfaces(grid);
    FAIL() << "expected ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("patches (row 0, column 0) and (row 0, column 1)"), std::string::npos)
        << e.what();
  }
  std::vector<std::vector<TensorSpline>> ragged = {{height_patch(0, 0, 3, 3), height_patch(1, 0, 3, 3)},
                                                   {height_patch(0, 1, 3, 3)}};
  EXPECT_THROW(join_surfaces(ragged), ModelError);
}

}  // namespace
}  // namespace trivox
