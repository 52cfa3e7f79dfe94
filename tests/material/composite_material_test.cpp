// Composition rules (composite_material.h) against values computed by hand.
#include "trivox/material/detail/composite_material.h"

#include <gtest/gtest.h>

#include <cmath>

#include "material/material_test_util.h"
#include "trivox/error.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/material/expression_material.h"

namespace trivox {
namespace {

MaterialPtr constant(std::vector<float> f) { return std::make_shared<ConstantMaterial>(std::move(f)); }

// A scalar source: one expression of the normalised parameters over the unit cube.
MaterialPtr scalar(const std::string& expression) {
  ExpressionParams p;
  p.expressions = {expression};
  return std::make_shared<ExpressionMaterial>(std::move(p), kUnitParamBox);
}

void expect_near(const std::vector<float>& got, const std::vector<float>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-6f) << "index " << i;
}

TEST(CompositeMaterial, BlendInterpolatesByTheClampedWeight) {
  const BlendMaterial blend(constant({1.0f, 0.0f}), constant({0.2f, 0.6f}), scalar("2 * u - 0.5"));
  expect_near(test::eval_one(blend, {0.5, 0, 0}), {0.6f, 0.3f});     // t = 0.5
  expect_near(test::eval_one(blend, {0.0, 0, 0}), {1.0f, 0.0f});     // t = -0.5 -> 0
  expect_near(test::eval_one(blend, {1.0, 0, 0}), {0.2f, 0.6f});     // t = 1.5 -> 1
  expect_near(test::eval_one(blend, {0.375, 0, 0}), {0.8f, 0.15f});  // t = 0.25
  EXPECT_THROW(BlendMaterial(constant({1.0f}), constant({0.2f, 0.6f}), scalar("u")), Error);
  EXPECT_THROW(BlendMaterial(constant({1.0f}), constant({0.2f}), constant({0.5f, 0.5f})), Error);
}

TEST(CompositeMaterial, ThresholdSplitsAtTheLevel) {
  const ThresholdMaterial t(scalar("w"), 0.5, constant({1.0f, 0.0f}), constant({0.0f, 0.7f}));
  expect_near(test::eval_one(t, {0, 0, 0.49}), {1.0f, 0.0f});
  expect_near(test::eval_one(t, {0, 0, 0.5}), {0.0f, 0.7f});  // at the level: above
  expect_near(test::eval_one(t, {0, 0, 0.9}), {0.0f, 0.7f});
  EXPECT_THROW(ThresholdMaterial(scalar("w"), NAN, constant({1.0f}), constant({0.0f})), Error);
}

TEST(CompositeMaterial, SelectTakesTheFirstRegionHolding) {
  // Cell domain [0, 2] x [0, 1] x [0, 1]: u = 1 is the normalised 0.5.
  const ParamBox cell{{0, 0, 0}, {2, 1, 1}};
  std::vector<SelectRegion> regions{{{{0, 0, 0}, {0.5, 1, 1}}, constant({1.0f, 0.0f})},
                                    {{{0.25, 0, 0}, {1, 0.5, 1}}, constant({0.0f, 1.0f})}};
  const SelectMaterial s(regions, constant({0.1f, 0.1f}), cell);
  expect_near(test::eval_one(s, {0.2, 0.9, 0.5}), {1.0f, 0.0f});
  expect_near(test::eval_one(s, {1.0, 0.2, 0.5}), {1.0f, 0.0f});  // in both (closed boxes): the first
  expect_near(test::eval_one(s, {1.5, 0.2, 0.5}), {0.0f, 1.0f});
  expect_near(test::eval_one(s, {1.5, 0.8, 0.5}), {0.1f, 0.1f});  // in none
  // A row mixing regions is the same as sample by sample.
  const std::vector<Vec3> row{{0.2, 0.9, 0.5}, {1.5, 0.2, 0.5}, {1.5, 0.8, 0.5}, {0.1, 0.1, 0.1}};
  const std::vector<float> all = test::eval_row(s, row, row);
  for (std::size_t i = 0; i < row.size(); ++i) {
    const std::vector<float> one = test::eval_one(s, row[i]);
    EXPECT_EQ(all[2 * i], one[0]);
    EXPECT_EQ(all[2 * i + 1], one[1]);
  }
  std::vector<SelectRegion> empty_box{{{{0.6, 0, 0}, {0.5, 1, 1}}, constant({1.0f, 0.0f})}};
  EXPECT_THROW(SelectMaterial(empty_box, constant({0.0f, 0.0f}), cell), Error);
}

TEST(CompositeMaterial, VoidMaskScalesTheMaterialDown) {
  const VoidMaskMaterial porous(constant({0.6f, 0.4f}), scalar("u"));
  expect_near(test::eval_one(porous, {0.25, 0, 0}), {0.45f, 0.3f});
  expect_near(test::eval_one(porous, {1.0, 0, 0}), {0.0f, 0.0f});
  expect_near(test::eval_one(porous, {0.0, 0, 0}), {0.6f, 0.4f});
  const VoidMaskMaterial clamped(constant({0.6f, 0.4f}), scalar("u - 2"));
  expect_near(test::eval_one(clamped, {0.5, 0, 0}), {0.6f, 0.4f});  // negative share: nothing removed
}

TEST(CompositeMaterial, TransferMapsTheSourceThroughTheStops) {
  std::vector<GradientStop> stops{{0.0, {1.0f, 0.0f}}, {2.0, {0.0f, 1.0f}}, {2.0, {0.5f, 0.5f}}};
  const TransferMaterial t(scalar("4 * u"), stops);
  expect_near(test::eval_one(t, {0.125, 0, 0}), {0.75f, 0.25f});  // s = 0.5
  expect_near(test::eval_one(t, {0.0, 0, 0}), {1.0f, 0.0f});
  expect_near(test::eval_one(t, {0.5, 0, 0}), {0.5f, 0.5f});  // at the step: the later stop
  expect_near(test::eval_one(t, {1.0, 0, 0}), {0.5f, 0.5f});  // above the last stop
  std::vector<GradientStop> decreasing{{1.0, {1.0f}}, {0.0, {0.0f}}};
  EXPECT_THROW(TransferMaterial(scalar("u"), decreasing), Error);
  EXPECT_THROW(TransferMaterial(constant({0.1f, 0.2f}), stops), Error);  // not a scalar source
}

}  // namespace
}  // namespace trivox
