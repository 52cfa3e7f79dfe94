// The scene's "greyscale" block and the printer keys of resin printers (docs/SCENE.md): what
// they read into, and each rule they break named at its JSON pointer.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/scene_test_util.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
using test::expect_scene_error;

ordered_json box(double size) {
  ordered_json points = ordered_json::array();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) points.push_back({i * size, j * size, k * size});
  return {{"orders", {2, 2, 2}}, {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}}, {"points", points}};
}

ordered_json resin_scene() {
  return {{"units", "mm"},
          {"printer", "sl1s"},
          {"materials", {{{"name", "stiff"}, {"rgba", {255, 128, 64}}}, {{"name", "soft"}, {"rgba", {64, 128, 255}}}}},
          {"greyscale", {{"source", {{"material", "stiff"}}}, {"curve", {{0, 40}, {0.5, 120}, {1, 250}}}}},
          {"cells",
           {{{"name", "a"}, {"geometry", box(4)}, {"material", "stiff"}},
            {{"name", "b"}, {"geometry", box(2)}, {"material", "soft"}}}}};
}

TEST(SceneGreyscale, MaterialSourceCurveAndDefaults) {
  const Scene s = parse_scene(resin_scene().dump(), "dir/resin.json");
  ASSERT_TRUE(s.greyscale.has_value());
  EXPECT_EQ(s.greyscale->material, 0);
  EXPECT_EQ(s.greyscale->antialiasing, 4);
  EXPECT_EQ(s.greyscale->curve.points(), (std::vector<GreyPoint>{{0, 40}, {0.5, 120}, {1, 250}}));
  EXPECT_FALSE(s.greyscale->exposure_s.has_value());
  for (const Cell& c : s.cells) EXPECT_FALSE(c.grey_source);
  EXPECT_EQ(s.printer.name, "sl1s");
  ASSERT_TRUE(s.printer.display.has_value());
  EXPECT_FALSE(parse_scene(
                   [] {
                     auto j = resin_scene();
                     j.erase("greyscale");
                     return j.dump();
                   }(),
                   "dir/resin.json")
                   .greyscale.has_value());
}

TEST(SceneGreyscale, ScalarSourceIsBuiltForEveryCell) {
  auto j = resin_scene();
  j["greyscale"] = {{"source", "u * 2"},
                    {"curve", {{0, 10}, {2, 250}}},
                    {"antialiasing", 8},
                    {"exposure_s", 3.5},
                    {"initial_exposure_s", 30}};
  const Scene s = parse_scene(j.dump(), "dir/resin.json");
  ASSERT_TRUE(s.greyscale.has_value());
  EXPECT_EQ(s.greyscale->material, -1);
  EXPECT_EQ(s.greyscale->antialiasing, 8);
  EXPECT_EQ(s.greyscale->exposure_s, 3.5);
  EXPECT_EQ(s.greyscale->initial_exposure_s, 30.0);
  for (const Cell& c : s.cells) {
    ASSERT_TRUE(c.grey_source);
    EXPECT_EQ(c.grey_source->num_materials(), 1);
    float v = 0;
    c.grey_source->evaluate({0.25, 0, 0}, {0, 0, 0}, std::span<float>(&v, 1));
    EXPECT_FLOAT_EQ(v, 0.5f);  // u over the cell's own domain [0, 1]
  }
}

TEST(SceneGreyscale, ErrorsNameThePointerAndTheRule) {
  auto bad = [](auto edit) {
    auto j = resin_scene();
    edit(j);
    return j.dump();
  };
  expect_scene_error(bad([](auto& j) {
                       j["greyscale"]["source"] = {{"material", "steel"}};
                     }),
                     "/greyscale/source/material", "\"steel\" is not a declared material");
  expect_scene_error(bad([](auto& j) {
                       j["greyscale"]["source"] = {{"material", "stiff"}, {"x", 1}};
                     }),
                     "/greyscale/source/x", "unknown key");
  expect_scene_error(bad([](auto& j) {
                       j["greyscale"]["curve"] = {{0, 40}, {0.5, 200}, {1, 100}};
                     }),
                     "/greyscale/curve", "monotone");
  expect_scene_error(bad([](auto& j) {
                       j["greyscale"]["curve"] = {{0, 40}, {0, 60}};
                     }),
                     "/greyscale/curve", "increase");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["curve"] = {{0, 300}}; }), "/greyscale/curve", "[0, 255]");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["curve"] = ordered_json::array(); }), "/greyscale/curve", "");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["curve"] = {{0, 40, 3}}; }), "/greyscale/curve/0", "");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["antialiasing"] = 9; }), "/greyscale/antialiasing", "9");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["antialiasing"] = 0; }), "/greyscale/antialiasing", "0");
  // Exposures outside what the printer's firmware takes (1 to 60 s, the first layers 10 to 120 s).
  expect_scene_error(bad([](auto& j) { j["greyscale"]["exposure_s"] = 0; }), "/greyscale/exposure_s",
                     "an exposure of 0 s is outside the 1 to 60 s the printer takes");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["exposure_s"] = 1e300; }), "/greyscale/exposure_s",
                     "an exposure of 1e+300 s is outside the 1 to 60 s");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["exposure_s"] = 0.5; }), "/greyscale/exposure_s", "0.5 s");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["initial_exposure_s"] = 121; }), "/greyscale/initial_exposure_s",
                     "an exposure of 121 s is outside the 10 to 120 s the printer takes");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["initial_exposure_s"] = -1e-300; }),
                     "/greyscale/initial_exposure_s", "outside the 10 to 120 s");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["dither"] = true; }), "/greyscale/dither", "unknown key");
  expect_scene_error(bad([](auto& j) { j["greyscale"].erase("curve"); }), "/greyscale", "curve");
  expect_scene_error(bad([](auto& j) { j["greyscale"]["source"] = "u +* 2"; }), "/greyscale/source", "expression");
}

TEST(SceneGreyscale, SquarePixelsOfAPitchAndResinPrintersWithOtherLayers) {
  auto j = resin_scene();
  j["printer"] = {{"pixel_mm", 0.05}, {"layer_thickness_mm", 0.035}, {"max_materials", 2}, {"name", "my lcd"}};
  Scene s = parse_scene(j.dump(), "dir/resin.json");
  EXPECT_DOUBLE_EQ(s.printer.pitch_x_mm(), 0.05);
  EXPECT_DOUBLE_EQ(s.printer.pitch_y_mm(), 0.05);
  EXPECT_EQ(s.printer.name, "my lcd");
  EXPECT_FALSE(s.printer.display.has_value());
  EXPECT_TRUE(s.printer.family.empty());

  j["printer"] = {{"base", "sl1"}, {"layer_thickness_mm", 0.035}};
  s = parse_scene(j.dump(), "dir/resin.json");
  ASSERT_TRUE(s.printer.display.has_value());
  EXPECT_EQ(s.printer.display->pixels_y, 1440);
  EXPECT_EQ(s.printer.layer_thickness_mm, 0.035);
  EXPECT_EQ(s.printer.family, "sl1");

  j["printer"] = {{"pixel_mm", 0.05}, {"x_dpi", 600}, {"layer_thickness_mm", 0.035}, {"max_materials", 2}};
  expect_scene_error(j.dump(), "/printer/pixel_mm", "not both");
  j["printer"] = {{"pixel_mm", 0.05}, {"max_materials", 2}};
  expect_scene_error(j.dump(), "/printer", "layer_thickness_mm");
  // A display whose pitch the profile would contradict.
  j["printer"] = {{"base", "sl1s"}, {"x_dpi", 600}};
  expect_scene_error(j.dump(), "/printer", "display");
}

}  // namespace
}  // namespace trivox
