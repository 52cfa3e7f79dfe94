// Scene files with named volumes, trims and unions: what they expand to, and the errors
// that name the file, the JSON pointer and the rule.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "scene/scene_test_util.h"
#include "support/test_support.h"
#include "trivox/scene/fraction_sums.h"

namespace trivox {
namespace {

std::string box(double x0, double x1) {
  return fmt::format(R"({{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[{0}, 0, 0], [{1}, 0, 0], [{0}, 2, 0], [{1}, 2, 0], [{0}, 0, 2], [{1}, 0, 2], [{0}, 2, 2], [{1}, 2, 2]]}})",
                     x0, x1);
}

std::string scene(const std::string& volumes_and_cells) {
  return R"({"version": 1, "units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
  "volumes": [{"name": "A", "geometry": )" +
         box(0, 4) + R"(}, {"name": "B", "geometry": )" + box(2, 6) + "}],\n" + volumes_and_cells + "}";
}

// A face of the unit cube as an inline bilinear surface.
std::string face(const std::string& p00, const std::string& p10, const std::string& p01, const std::string& p11) {
  return R"({"orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [)" + p00 + "," + p10 + "," + p01 +
         "," + p11 + "]}";
}

TEST(SceneTrim, UnionExpandsIntoMutuallyExclusiveCells) {
  const Scene s = parse_scene(scene(R"("unions": [{"name": "u", "volumes": ["A", "B"], "regions": [
      {"of": ["A"], "material": "VeroCyan"}, {"of": ["B"], "material": "VeroMagenta"},
      {"of": ["A", "B"], "parametrize": "B", "material": "VeroCyan"}]}])"),
                              "scene.json");
  ASSERT_EQ(s.cells.size(), 3u);
  EXPECT_EQ(s.cells[0].name, "u/A");
  EXPECT_EQ(s.cells[2].name, "u/A+B");
  EXPECT_EQ(s.cells[0].scene_volume, 0);
  ASSERT_EQ(s.cells[0].trim.clauses.size(), 1u);
  EXPECT_EQ(s.cells[0].trim.clauses[0].volume, 1);
  EXPECT_EQ(s.cells[0].trim.clauses[0].side, TrimSide::kOutside);
  EXPECT_EQ(s.cells[1].scene_volume, 1);
  EXPECT_EQ(s.cells[1].trim.clauses[0].side, TrimSide::kOutside);
  EXPECT_EQ(s.cells[2].scene_volume, 1);
  EXPECT_EQ(s.cells[2].trim.clauses[0].volume, 0);
  EXPECT_EQ(s.cells[2].trim.clauses[0].side, TrimSide::kInside);
}

// The fraction check of a trimmed cell covers its whole volume: a point where the material
// breaks the rule may lie outside the cell, so it is "cannot prove", the point named; the
// untrimmed cells are proved.
TEST(SceneTrim, FractionCheckOfATrimmedCellCannotProveWhatTheTrimMayCut) {
  const Scene s = parse_scene(
      scene(R"("unions": [{"name": "u", "volumes": ["A", "B"], "regions": [
      {"of": ["A"], "material": {"kind": "expression", "fractions": {"VeroCyan": "u + 0.5", "VeroMagenta": "1 - u"}}},
      {"of": ["B"], "material": "VeroMagenta"},
      {"of": ["A", "B"], "material": "VeroCyan"}]}],
      "cells": [{"name": "plain", "geometry": )" +
            box(10, 12) +
            R"(, "material": {"kind": "expression", "fractions": {"VeroCyan": "1 - w", "VeroMagenta": "w"}}}])"),
      "scene.json");
  const std::vector<CellFractionCheck> checks = check_scene_fractions(s);
  ASSERT_EQ(checks.size(), 4u);
  EXPECT_EQ(checks[0].check.outcome, FractionCheckOutcome::kProved) << checks[0].check.reason;  // "plain"
  EXPECT_EQ(checks[1].check.outcome, FractionCheckOutcome::kUnproved);                          // "u/A"
  EXPECT_NE(checks[1].check.reason.find("sum to"), std::string::npos) << checks[1].check.reason;
  EXPECT_NE(checks[1].check.reason.find("trim may cut away"), std::string::npos) << checks[1].check.reason;
  EXPECT_EQ(checks[2].check.outcome, FractionCheckOutcome::kProved);
  EXPECT_EQ(checks[3].check.outcome, FractionCheckOutcome::kProved);
}

TEST(SceneTrim, UnknownTrimVolumeNamesTheFieldAndTheNames) {
  test::expect_scene_error(
      scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "outside", "volume": "C"}]}])"),
      "/cells/0/trim/0/volume", "there is no volume \"C\" in \"volumes\"; the names are \"A\", \"B\"");
}

TEST(SceneTrim, BadSideIsRefused) {
  test::expect_scene_error(
      scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "within", "volume": "B"}]}])"),
      "/cells/0/trim/0/side", "expected \"inside\" or \"outside\", got \"within\"");
}

TEST(SceneTrim, OwnVolumeIsRefused) {
  test::expect_scene_error(
      scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside", "volume": "A"}]}])"),
      "/cells/0/trim/0/volume", "the cell's own volume");
}

TEST(SceneTrim, MissingUnionRegionIsRefused) {
  test::expect_scene_error(scene(R"("unions": [{"name": "u", "volumes": ["A", "B"], "regions": [
      {"of": ["A"], "material": "VeroCyan"}, {"of": ["B"], "material": "VeroMagenta"}]}])"),
                           "/unions/0/regions", "no region covers the points inside exactly [\"A\", \"B\"]");
}

TEST(SceneTrim, OpenShellIsAnInputErrorNamingTheShell) {
  // Five faces of the unit cube: the top is missing.
  const std::string faces =
      face("[0,0,0]", "[0,1,0]", "[0,0,1]", "[0,1,1]") + "," + face("[1,0,0]", "[1,1,0]", "[1,0,1]", "[1,1,1]") + "," +
      face("[0,0,0]", "[1,0,0]", "[0,0,1]", "[1,0,1]") + "," + face("[0,1,0]", "[1,1,0]", "[0,1,1]", "[1,1,1]") + "," +
      face("[0,0,0]", "[1,0,0]", "[0,1,0]", "[1,1,0]");
  test::expect_scene_error(scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "shell": {"surfaces": [)" + faces +
                                 "]}}]}]"),
                           "/cells/0/trim/0/shell", "is not closed");
  // With the top the same shell reads.
  const std::string closed = faces + "," + face("[0,0,1]", "[1,0,1]", "[0,1,1]", "[1,1,1]");
  const Scene s = parse_scene(scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "parametric": {"surfaces": [)" +
                                    closed + "]}}]}]"),
                              "scene.json");
  ASSERT_EQ(s.cells.size(), 1u);
  EXPECT_EQ(s.cells[0].trim.clauses[0].kind, TrimKind::kParametric);
  EXPECT_EQ(s.cells[0].trim.clauses[0].shell->surfaces.size(), 6u);
}

TEST(SceneTrim, OpenShellFromAFileNamesTheFile) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  // The Utah teapot's 32 Bezier patches leave the bottom open.
  const std::string file = (dir / "surfaces" / "teapot_bezier_patches.xml").string();
  test::expect_scene_error(scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "shell": {"file": ")" + file +
                                 R"("}}]}])"),
                           "/cells/0/trim/0/shell/file", "teapot_bezier_patches.xml\" is not closed");
}

TEST(SceneTrim, DuckShellReads) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const std::string file = (dir / "surfaces" / "duck_brep.xml").string();
  const Scene s = parse_scene(scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "shell": {"file": ")" + file + R"(", "placement": {"scale": 10}}}]}])"),
                              "scene.json");
  EXPECT_EQ(s.cells[0].trim.clauses[0].shell->surfaces.size(), 6u);
}

TEST(SceneTrim, TrimmedModelShellReadsAndAnOpenOneNamesTheSurfaceAndSegment) {
  // A square trimmed out of a plane: a surface, not a closed shell.
  const auto dir = test::scratch_dir();
  test::write_file(dir / "square.itd", R"([OBJECT SQUARE
  [MODEL 1 2
    [MDLTSRF 1
      [SURFACE BSPLINE 2 2 2 2 E3 [KV 0 0 1 1] [KV 0 0 1 1] [0 0 0] [1 0 0] [0 1 0] [1 1 0]]
      [MDLLOOP 1 2]
    ]
    [MDLTSEG 1 1 0 [CURVE BSPLINE 3 2 E2 [KV 0 0 1 2 2] [0.2 0.2] [0.8 0.2] [0.8 0.8]]]
    [MDLTSEG 1 1 0 [CURVE BSPLINE 2 2 E2 [KV 0 0 1 1] [0.8 0.8] [0.2 0.2]]]
  ]
]
)");
  test::expect_scene_error(
      scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "shell": {"file": "square.itd"}}]}])"),
      "/cells/0/trim/0/shell",
      "MODEL 'SQUARE' (line 2), trimmed surface 1 (line 3): trimming segment 1 borders one surface "
      "and no other segment lies near it",
      dir);
  const auto shared = test::shared_data_dir();
  if (shared.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const std::string file = (shared / "surfaces" / "teapot_trimmed_model.itd").string();
  const Scene s = parse_scene(scene(R"("cells": [{"volume": "A", "material": "VeroCyan", "trim": [{"side": "inside",
      "shell": {"file": ")" + file + R"("}}]}])"),
                              "scene.json");
  const TrimShell& shell = *s.cells[0].trim.clauses[0].shell;
  EXPECT_TRUE(shell.surfaces.empty());
  ASSERT_EQ(shell.trimmed.size(), 6u);
  EXPECT_EQ(shell.trimmed[0].loops.size(), 3u);
  EXPECT_EQ(shell.trimmed[0].loops[2].size(), 8u);
  EXPECT_TRUE(shell.trimmed[0].loops[2][1].reversed);  // segment -7
  EXPECT_EQ(shell.trimmed[0].loops[2][1].segment, 6);
}

}  // namespace
}  // namespace trivox
