// invert_certified (trivox/inverse/invert.h): Newton first, the global solver where Newton
// does not converge. On a solid cylinder revolved from a rectangle touching the axis, Newton
// from the domain's centre stops SINGULAR for about half of its points (det J vanishes on the
// axis, which the centre's iteration crosses); the certified inverse solves every one, agrees
// with Newton wherever Newton converged, and proves the points beyond the cylinder outside.
#include <random>

#include <gtest/gtest.h>

#include "trivox/construct/revolve.h"
#include "trivox/inverse/invert.h"

namespace trivox {
namespace {

Volume solid_cylinder() {
  // The rectangle x in [0, 10], z in [0, 10] of the xz plane, turned once around z.
  const KnotVector kv(2, {0, 0, 1, 1});
  const TensorSpline profile({kv, kv}, 3, std::vector<double>{0, 0, 0, 10, 0, 0, 0, 0, 10, 10, 0, 10});
  return revolve(profile, RevolveParams{}).volume;
}

TEST(CertifiedInverse, SolvesWhereNewtonFromTheCentreStopsAndAgreesWhereItConverged) {
  const Volume v = solid_cylinder();
  const GlobalSolver solver(v);
  const ParamBox d = v.domain();
  const Vec3 centre = d.center();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> t(0.001, 0.999);
  int newton_failed = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p{d.lo.x + t(rng) * (d.hi.x - d.lo.x), d.lo.y + t(rng) * (d.hi.y - d.lo.y),
                 d.lo.z + t(rng) * (d.hi.z - d.lo.z)};
    const Vec3 x = v.evaluate(p);
    const InverseResult newton = invert(v, x, centre);
    const InverseResult r = invert_certified(v, solver, x, centre);
    ASSERT_EQ(r.status, InverseStatus::kConverged) << i;
    EXPECT_LE(norm(v.evaluate(r.uvw) - x), 1e-6) << i;
    EXPECT_TRUE(d.contains(r.uvw));
    if (newton.status == InverseStatus::kConverged) {
      EXPECT_EQ(r.uvw.x, newton.uvw.x);  // Newton's own answer, untouched
      EXPECT_EQ(r.iterations, newton.iterations);
    } else {
      ++newton_failed;
    }
  }
  EXPECT_GT(newton_failed, 500);  // the case that needs the fallback is really exercised
  for (const Vec3 x : {Vec3{20, 0, 5}, Vec3{0, 0, -1}, Vec3{7, 0, 10.5}}) {
    const InverseResult r = invert_certified(v, solver, x, centre);
    EXPECT_EQ(r.status, InverseStatus::kOutside);
    EXPECT_TRUE(d.contains(r.uvw));
  }
}

}  // namespace
}  // namespace trivox
