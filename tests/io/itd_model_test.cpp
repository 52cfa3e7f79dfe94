// IRIT trimmed-surface models (MODEL): the structure the reader keeps, and the errors that
// name the file, the line, the model and the rule.
#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

// One planar square surface trimmed by a loop of four one-sided segments (a triangle-free
// square in the middle of its domain), written with the given loop and second segment.
std::string square_model(const std::string& loop = "1 2 3 4", const std::string& segment2 = "1 1 0") {
  auto seg = [](const std::string& head, double u0, double v0, double u1, double v1) {
    return "    [MDLTSEG " + head + "\n      [CURVE BSPLINE 2 2 E2 [KV 0 0 1 1] [" + std::to_string(u0) + " " +
           std::to_string(v0) + "] [" + std::to_string(u1) + " " + std::to_string(v1) + "]]\n    ]\n";
  };
  return "[OBJECT SQUARE\n  [MODEL 1 4\n    [MDLTSRF 1\n"
         "      [SURFACE BSPLINE 2 2 2 2 E3 [KV 0 0 1 1] [KV 0 0 1 1] [0 0 0] [1 0 0] [0 1 0] [1 1 0]]\n"
         "      [MDLLOOP " +
         loop + "]\n    ]\n" + seg("1 1 0", 0.25, 0.25, 0.75, 0.25) + seg(segment2, 0.75, 0.25, 0.75, 0.75) +
         seg("1 1 0", 0.75, 0.75, 0.25, 0.75) + seg("1 1 0", 0.25, 0.75, 0.25, 0.25) + "  ]\n]\n";
}

TEST(ItdModel, KeepsSurfacesLoopsAndSegments) {
  const Model m = read_itd(square_model("1 2 -3 4"), "square.itd");
  ASSERT_EQ(m.patches.size(), 1u);  // the untrimmed surface; the curves are not patches
  ASSERT_EQ(m.trimmed_models.size(), 1u);
  const TrimmedModel& t = m.trimmed_models[0];
  EXPECT_EQ(t.name, "SQUARE");
  ASSERT_EQ(t.surfaces.size(), 1u);
  EXPECT_EQ(t.surfaces[0].patch, 0);
  EXPECT_EQ(t.surfaces[0].source_line, 3);
  ASSERT_EQ(t.surfaces[0].loops.size(), 1u);
  EXPECT_EQ(t.surfaces[0].loops[0], (std::vector<int>{1, 2, -3, 4}));
  ASSERT_EQ(t.segments.size(), 4u);
  EXPECT_EQ(t.segments[1].surfaces, std::vector<int>{0});
  ASSERT_EQ(t.segments[1].curves.size(), 1u);
  EXPECT_EQ(t.segments[1].curves[0].point_dim(), 2);
  EXPECT_DOUBLE_EQ(t.segments[1].curves[0].point(1)[1], 0.75);
}

void expect_error(const std::string& text, int line, const std::string& fragment) {
  try {
    read_itd(text, "bad.itd");
    ADD_FAILURE() << "no error; expected '" << fragment << "'";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("MODEL in object 'SQUARE'"), std::string::npos) << e.what();
  }
}

TEST(ItdModel, BrokenModelsNameTheLineAndTheRule) {
  expect_error(square_model("1 2 9 4"), 3, "refers to segment 9, but the MODEL's segments are 1..4");
  expect_error(square_model("1 0 3 4"), 5, "lists segment numbers");
  expect_error(square_model("1 2 3 4", "1 7 0"), 10, "borders surface 7, but the MODEL's surfaces are 1..1");
  std::string two_sided = square_model("1 2 3 4", "3 1 1");
  expect_error(two_sided, 10, "the curve mask 3 announces 2 curve(s)");
  std::string miscounted = square_model();
  miscounted.replace(miscounted.find("MODEL 1 4"), 9, "MODEL 1 5");
  expect_error(miscounted, 2, "declares 5 trimming segments (MDLTSEG) and holds 4");
}

TEST(ItdModel, TeapotModelFromSharedData) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model m = read_model(dir / "surfaces" / "teapot_trimmed_model.itd");
  ASSERT_EQ(m.trimmed_models.size(), 1u);
  const TrimmedModel& t = m.trimmed_models[0];
  EXPECT_EQ(t.name, "TEAPOT");
  ASSERT_EQ(t.surfaces.size(), 6u);
  ASSERT_EQ(t.segments.size(), 15u);
  EXPECT_EQ(m.patches.size(), 6u);
  // The body: two holes (handle ends) and the outer loop that runs along its seam.
  EXPECT_EQ(t.surfaces[0].loops, (std::vector<std::vector<int>>{{4}, {5}, {8, -7, 9, -2, 10, -6, 11, 3}}));
  // Segment 1 joins the spout and its cap; segment 8 is a seam of the body only.
  EXPECT_EQ(t.segments[0].surfaces, (std::vector<int>{1, 5}));
  EXPECT_EQ(t.segments[0].curves.size(), 2u);
  EXPECT_EQ(t.segments[0].curves[0].num_ctrl(0), 76);
  EXPECT_EQ(t.segments[7].surfaces, std::vector<int>{0});
}

}  // namespace
}  // namespace trivox
