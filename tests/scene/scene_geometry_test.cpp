// Scene geometry: model files with patch selection, fields read from files, and placements.
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/scene_test_util.h"
#include "support/test_support.h"
#include "trivox/io/model.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
using test::expect_scene_error;

TensorSpline box_spline(Vec3 lo, Vec3 hi) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z});
  return TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts);
}

// A model file with two box volumes side by side and a two-component material field.
void write_models(const std::filesystem::path& dir) {
  Model boxes;
  boxes.source = "boxes";
  boxes.patches.push_back({"LEFT", 0, 0, box_spline({0, 0, 0}, {10, 10, 10})});
  boxes.patches.push_back({"RIGHT", 1, 0, box_spline({10, 0, 0}, {20, 10, 10})});
  std::ofstream(dir / "boxes.itd") << [&] {
    std::ostringstream s;
    write_itd(s, boxes);
    return s.str();
  }();
  Model field;
  field.source = "field";
  std::vector<double> pts;
  for (int c = 0; c < 8; ++c) pts.insert(pts.end(), {(c & 1) ? 1.0 : 0.0, (c & 1) ? 0.0 : 1.0});
  field.patches.push_back(
      {"FIELD", 0, 0, TensorSpline({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 2, pts)});
  std::ofstream(dir / "field.itd") << [&] {
    std::ostringstream s;
    write_itd(s, field);
    return s.str();
  }();
}

ordered_json scene_with(const ordered_json& geometry, const ordered_json& material) {
  return {{"units", "mm"},
          {"printer", "j750-hq"},
          {"materials", {{{"name", "A"}, {"rgba", {255, 0, 0}}}, {{"name", "B"}, {"rgba", {0, 0, 255}}}}},
          {"cells", {{{"name", "part"}, {"geometry", geometry}, {"material", material}}}}};
}

const ordered_json kConstant = {{"kind", "constant"}, {"fractions", {{"A", 1}}}};

TEST(SceneGeometry, PatchSelectionFromAFile) {
  const auto dir = test::scratch_dir();
  write_models(dir);
  const auto source = dir / "scene.json";
  Scene scene = parse_scene(scene_with({{"file", "boxes.itd"}, {"patch", 1}}, kConstant).dump(), source);
  ASSERT_EQ(scene.cells.size(), 1u);
  EXPECT_EQ(scene.cells[0].volume.evaluate({0, 0, 0}), (Vec3{10, 0, 0}));
  scene = parse_scene(scene_with({{"file", "boxes.itd"}, {"patch", "all"}}, kConstant).dump(), source);
  ASSERT_EQ(scene.cells.size(), 2u);
  EXPECT_EQ(scene.cells[0].name, "part/0");
  EXPECT_EQ(scene.cells[1].name, "part/1");
  EXPECT_EQ(scene.cells[1].pointer, "/cells/0");
  EXPECT_EQ(scene.bounds().hi, (Vec3{20, 10, 10}));
  // Two trivariates and no "patch": ambiguous.
  expect_scene_error(scene_with({{"file", "boxes.itd"}}, kConstant).dump(), "/cells/0/geometry", "\"all\"", dir);
  expect_scene_error(scene_with({{"file", "boxes.itd"}, {"patch", 2}}, kConstant).dump(), "/cells/0/geometry/patch",
                     "outside [0, 1]", dir);
  expect_scene_error(scene_with({{"file", "boxes.itd"}, {"patch", "some"}}, kConstant).dump(),
                     "/cells/0/geometry/patch", "\"all\"", dir);
  // A field file is not geometry.
  expect_scene_error(scene_with({{"file", "field.itd"}}, kConstant).dump(), "/cells/0/geometry", "geometry needs 3",
                     dir);
}

TEST(SceneGeometry, FieldFromAFileMapsOntoEachCell) {
  const auto dir = test::scratch_dir();
  write_models(dir);
  const ordered_json material = {
      {"kind", "spline_field"}, {"components", {"B", "A"}}, {"field", {{"file", "field.itd"}}}};
  const Scene scene =
      parse_scene(scene_with({{"file", "boxes.itd"}, {"patch", "all"}}, material).dump(), dir / "scene.json");
  ASSERT_EQ(scene.cells.size(), 2u);
  for (const Cell& cell : scene.cells) {
    std::vector<float> f(2);
    cell.material->evaluate({0.25, 0.5, 0.5}, {}, f);  // component 0 = u -> B, component 1 = 1-u -> A
    EXPECT_NEAR(f[1], 0.25, 1e-6);
    EXPECT_NEAR(f[0], 0.75, 1e-6);
  }
  ordered_json wrong = material;
  wrong["components"] = {"A"};
  expect_scene_error(scene_with({{"file", "boxes.itd"}, {"patch", 0}}, wrong).dump(), "/cells/0/material/field",
                     "has 2 component(s); this field needs 1", dir);
}

TEST(SceneGeometry, IritScalarFieldDrivesAGradient) {
  const auto shared = test::shared_data_dir();
  if (shared.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const ordered_json geometry = {
      {"orders", {2, 2, 2}},
      {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}},
      {"points", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}}};
  const ordered_json material = {
      {"kind", "scalar_gradient"},
      {"field", {{"file", (shared / "volumes/irit/sphere16.itd").string()}}},
      {"stops", {{{"value", 0.0}, {"fractions", {{"A", 1}}}}, {{"value", 1.0}, {"fractions", {{"B", 1}}}}}}};
  const Scene scene = parse_scene(scene_with(geometry, material).dump(), "s.json");
  std::vector<float> f(2);
  scene.cells[0].material->evaluate({0.5, 0.5, 0.5}, {}, f);
  EXPECT_NEAR(f[0] + f[1], 1.0, 1e-5);
}

const ordered_json kUnitBox = {
    {"orders", {2, 2, 2}},
    {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}},
    {"points", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}}};

Volume placed(const ordered_json& placement) {
  ordered_json s = scene_with(kUnitBox, kConstant);
  s["cells"][0]["placement"] = placement;
  return parse_scene(s.dump(), "s.json").cells[0].volume;
}

void expect_near(Vec3 a, Vec3 b) {
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
}

TEST(SceneGeometry, PlacementScaleRotateTranslate) {
  // Scale (2, 3, 4), then a quarter turn about z, then a move by (10, 20, 30):
  // (x, y, z) -> (10 - 3y, 20 + 2x, 30 + 4z).
  const Volume v = placed({{"translate", {10, 20, 30}}, {"rotate_deg", {0, 0, 90}}, {"scale", {2, 3, 4}}});
  expect_near(v.evaluate({1, 0, 0}), {10, 22, 30});
  expect_near(v.evaluate({0, 1, 0}), {7, 20, 30});
  expect_near(v.evaluate({0.5, 0.5, 1}), {8.5, 21, 34});
  // The same as a matrix.
  const Volume m = placed({{"matrix", {{0, -3, 0, 10}, {2, 0, 0, 20}, {0, 0, 4, 30}, {0, 0, 0, 1}}}});
  expect_near(m.evaluate({0.5, 0.5, 1}), {8.5, 21, 34});
  // Rotations about x, then y: (0,1,0) -> x by 90 -> (0,0,1) -> y by 90 -> (1,0,0).
  expect_near(placed({{"rotate_deg", {90, 90, 0}}}).evaluate({0, 1, 0}), {1, 0, 0});
  expect_near(placed({{"scale", 5}}).evaluate({1, 1, 1}), {5, 5, 5});
}

TEST(SceneGeometry, PlacementRules) {
  ordered_json s = scene_with(kUnitBox, kConstant);
  s["cells"][0]["placement"] = {{"scale", {1, 0, 1}}};
  expect_scene_error(s.dump(), "/cells/0/placement", "singular");
  s["cells"][0]["placement"] = {{"matrix", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0.1, 1}}}};
  expect_scene_error(s.dump(), "/cells/0/placement/matrix/3", "[0, 0, 0, 1]");
  s["cells"][0]["placement"] = {{"matrix", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}, {"scale", 2}};
  expect_scene_error(s.dump(), "/cells/0/placement", "leave out");
  s["cells"][0]["placement"] = {{"rotate", {0, 0, 1}}};
  expect_scene_error(s.dump(), "/cells/0/placement/rotate", "\"rotate_deg\"");
}

TEST(SceneGeometry, FoldedCellIsRefusedMirroredCellIsKept) {
  // Moving one corner of the top face across the opposite side makes det J change sign.
  ordered_json folded = kUnitBox;
  folded["points"][5] = {-1, 0, 1};
  expect_scene_error(scene_with(folded, kConstant).dump(), "/cells/0/geometry", "folds over itself");
  // A mirror (det J < 0 everywhere) is a valid, left-handed cell.
  ordered_json s = scene_with(kUnitBox, kConstant);
  s["cells"][0]["placement"] = {{"scale", {-1, 1, 1}}};
  EXPECT_EQ(parse_scene(s.dump(), "s.json").cells.size(), 1u);
}

TEST(SceneGeometry, RationalInlineVolumeIsExact) {
  // A quarter annulus (radii 1 and 2) from inline NURBS control points: every point of the
  // face u = 1 lies at radius 2.
  const double h = std::numbers::sqrt2 / 2;
  ordered_json g = {{"orders", {2, 3, 2}}, {"knots", {{0, 0, 1, 1}, {0, 0, 0, 1, 1, 1}, {0, 0, 1, 1}}}};
  ordered_json pts = ordered_json::array(), w = ordered_json::array();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) {
        const double r = 1.0 + i, xy[3][2] = {{1, 0}, {1, 1}, {0, 1}};
        pts.push_back({r * xy[j][0], r * xy[j][1], k});
        w.push_back(j == 1 ? h : 1.0);
      }
  g["points"] = pts;
  g["weights"] = w;
  const Volume v = parse_scene(scene_with(g, kConstant).dump(), "s.json").cells[0].volume;
  for (double t : {0.1, 0.37, 0.5, 0.9}) {
    const Vec3 p = v.evaluate({1, t, 0.5});
    EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-12);
  }
}

}  // namespace
}  // namespace trivox
