// The evaluation kernels on every SIMD target this processor runs (include/trivox/simd.h),
// each forced in turn: the targets that fuse multiply-adds (avx512, avx2) give the same numbers
// bit for bit, every other target agrees with them to within a few units in the last place,
// the Bezier nets' bounds (no fused arithmetic) agree everywhere, and a slice of a bundled
// example is the same on every target.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/scene/scene.h"
#include "trivox/simd.h"
#include "trivox/slice/slicer.h"
#include "trivox/spline/volume.h"

namespace trivox {
namespace {

bool fuses(const std::string& target) { return target == "avx512" || target == "avx2"; }

// Restores the best target when a test ends, whatever it forced.
struct BestTargetAfterwards {
  ~BestTargetAfterwards() { use_simd_target("best"); }
};

TEST(SimdTargets, ListStartsWithTheTargetInUseAndEachCanBeChosen) {
  BestTargetAfterwards restore;
  const std::vector<std::string> targets = simd_targets();
  ASSERT_FALSE(targets.empty());
  EXPECT_EQ(simd_target(), targets.front());
  for (const std::string& t : targets) {
    use_simd_target(t);
    EXPECT_EQ(simd_target(), t);
  }
  use_simd_target("best");
  EXPECT_EQ(simd_target(), targets.front());
  EXPECT_THROW(use_simd_target("avx3"), InputError);
  EXPECT_THROW(use_simd_target(""), InputError);
  // A rejected name leaves the choice as it was.
  EXPECT_EQ(simd_target(), targets.front());
}

// A rational version of the test column: the same control points with weights from 0.25 to 4,
// so that the quotient rule of every kernel is exercised.
Volume rational_column(const VolumeOptions& options) {
  const Volume base = test::twisted_bent_box(40, 30, 60);
  const TensorSpline& s = base.spline();
  std::vector<double> weights(s.points().size() / 3);
  for (std::size_t i = 0; i < weights.size(); ++i) weights[i] = std::ldexp(1.0, static_cast<int>(i % 5) - 2);
  return Volume(TensorSpline({s.knots(0), s.knots(1), s.knots(2)}, 3,
                             std::vector<double>(s.points().begin(), s.points().end()), weights),
                options);
}

struct Evaluations {
  std::vector<Vec3> values, many, jac_values;
  std::vector<Mat3> jacobians;
};

// Values, values in groups (evaluate_many) and Jacobians at fixed random parameters, with the
// kernels of the target in use when the volume is built.
Evaluations evaluate_all(bool power_form, bool rational) {
  VolumeOptions options;
  options.power_form = power_form;
  const Volume v = rational ? rational_column(options) : Volume(test::twisted_bent_box(40, 30, 60).spline(), options);
  EXPECT_EQ(v.kernel(), power_form ? VolumeKernel::kPowerForm : VolumeKernel::kDeBoor);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> uvw(203);
  for (Vec3& p : uvw) {
    const ParamBox& d = v.domain();
    p = {d.lo.x + unit(rng) * (d.hi.x - d.lo.x), d.lo.y + unit(rng) * (d.hi.y - d.lo.y),
         d.lo.z + unit(rng) * (d.hi.z - d.lo.z)};
  }
  Evaluations e;
  e.values.resize(uvw.size());
  e.many.resize(uvw.size());
  e.jac_values.resize(uvw.size());
  e.jacobians.resize(uvw.size());
  for (std::size_t i = 0; i < uvw.size(); ++i) {
    e.values[i] = v.evaluate(uvw[i]);
    v.evaluate_jacobian(uvw[i], e.jac_values[i], e.jacobians[i]);
  }
  v.evaluate_many(uvw, e.many);
  return e;
}

void expect_same(const Evaluations& a, const Evaluations& b, bool exact, const std::string& what) {
  // Coordinates are up to about 60 mm and Jacobian entries up to about 100 mm per unit: a
  // few ulps of those.
  const double tol_value = exact ? 0.0 : 1e-12 * 64, tol_jacobian = exact ? 0.0 : 1e-12 * 128;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(a.values[i][c], b.values[i][c], tol_value) << what << " point " << i;
      ASSERT_NEAR(a.many[i][c], b.many[i][c], tol_value) << what << " point " << i;
      ASSERT_NEAR(a.jac_values[i][c], b.jac_values[i][c], tol_value) << what << " point " << i;
      for (int r = 0; r < 3; ++r)
        ASSERT_NEAR(a.jacobians[i].m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)],
                    b.jacobians[i].m[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)], tol_jacobian)
            << what << " point " << i;
    }
    if (exact) {  // bit for bit, so also no sign-of-zero or NaN difference
      ASSERT_EQ(std::memcmp(&a.values[i], &b.values[i], sizeof(Vec3)), 0) << what << " point " << i;
      ASSERT_EQ(std::memcmp(&a.jacobians[i], &b.jacobians[i], sizeof(Mat3)), 0) << what << " point " << i;
    }
    // Within one target, evaluate_many is evaluate bit for bit (documented in volume.h).
    ASSERT_EQ(std::memcmp(&a.values[i], &a.many[i], sizeof(Vec3)), 0) << what << " point " << i;
  }
}

TEST(SimdTargets, KernelsAgreeOnEveryTargetAndFusedTargetsBitForBit) {
  BestTargetAfterwards restore;
  const std::vector<std::string> targets = simd_targets();
  for (const bool power_form : {true, false})
    for (const bool rational : {false, true}) {
      use_simd_target(targets.front());
      const Evaluations reference = evaluate_all(power_form, rational);
      for (const std::string& t : targets) {
        use_simd_target(t);
        const std::string what = t + (power_form ? " power form" : " de Boor") + (rational ? " rational" : "");
        expect_same(evaluate_all(power_form, rational), reference, fuses(t) == fuses(targets.front()) && fuses(t),
                    what);
      }
    }
}

TEST(SimdTargets, GlobalSolverFindsTheSamePreimagesOnEveryTarget) {
  BestTargetAfterwards restore;
  const std::vector<std::string> targets = simd_targets();
  std::vector<Vec3> points;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-5.0, 65.0);
  for (int i = 0; i < 60; ++i) points.push_back({coord(rng), coord(rng), coord(rng)});
  auto solve_all = [&] {
    const Volume v = test::twisted_bent_box(40, 30, 60);
    const GlobalSolver solver(v);
    std::vector<GlobalResult> out;
    for (const Vec3& x : points) out.push_back(solver.solve(x));
    return out;
  };
  use_simd_target(targets.front());
  const std::vector<GlobalResult> reference = solve_all();
  int found = 0;
  for (const std::string& t : targets) {
    use_simd_target(t);
    const std::vector<GlobalResult> got = solve_all();
    for (std::size_t i = 0; i < points.size(); ++i) {
      ASSERT_EQ(got[i].status, reference[i].status) << t << " point " << i;
      ASSERT_EQ(got[i].preimages.size(), reference[i].preimages.size()) << t << " point " << i;
      for (std::size_t k = 0; k < got[i].preimages.size(); ++k)
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(got[i].preimages[k].uvw[c], reference[i].preimages[k].uvw[c], fuses(t) ? 0.0 : 1e-12)
              << t << " point " << i;
      found += static_cast<int>(got[i].preimages.size());
    }
  }
  EXPECT_GT(found, 0);  // some points are inside
}

TEST(SimdTargets, ExampleLayersAreTheSameOnEveryTarget) {
  BestTargetAfterwards restore;
  const std::vector<std::string> targets = simd_targets();
  const auto path = std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "scenes" / "twisted_column_porous.json";
  auto slice_some = [&] {
    const Scene scene = read_scene(path);
    const Slicer slicer(scene, {});
    std::vector<std::pair<LayerResult, LayerRasters>> out;
    for (int layer : {300, 900, 1500}) {
      LayerResult r = slicer.slice_layer(layer, {.rasters = true});
      LayerRasters rasters = std::move(r.rasters);
      out.emplace_back(std::move(r), std::move(rasters));
    }
    return out;
  };
  use_simd_target(targets.front());
  const auto reference = slice_some();
  for (const std::string& t : targets) {
    use_simd_target(t);
    const auto got = slice_some();
    for (std::size_t l = 0; l < got.size(); ++l) {
      const MaterialGrid& a = got[l].second.fractions;
      const MaterialGrid& b = reference[l].second.fractions;
      ASSERT_EQ(a.width_px(), b.width_px());
      ASSERT_EQ(a.height_px(), b.height_px());
      std::size_t inside = 0;
      for (int y = 0; y < a.height_px(); ++y)
        for (int x = 0; x < a.width_px(); ++x)
          for (int m = 0; m < a.num_materials(); ++m) {
            ASSERT_EQ(a.at(x, y, m), b.at(x, y, m)) << t << " layer " << l << " pixel " << x << "," << y;
            inside += a.at(x, y, m) > 0 ? 1 : 0;
          }
      EXPECT_GT(inside, 1000u);
      EXPECT_TRUE(got[l].first.labels == reference[l].first.labels) << t << " layer " << l;
    }
  }
}

}  // namespace
}  // namespace trivox
