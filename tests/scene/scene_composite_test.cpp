// Scene files with textures, transfer functions and composed material functions: what they
// build evaluates to the hand-computed fractions, and their mistakes name the JSON pointer.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene_test_util.h"
#include "support/test_support.h"
#include "trivox/output/png_io.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
using test::expect_scene_error;

// A 10 mm box cell (parameters [0,1]^3) with `material`, materials A and B.
ordered_json scene_with(const ordered_json& material) {
  return {{"units", "mm"},
          {"printer", "j750-paper"},
          {"materials", {{{"name", "A"}, {"rgba", {255, 0, 0}}}, {{"name", "B"}, {"rgba", {0, 0, 255}}}}},
          {"cells",
           {{{"geometry",
              {{"orders", {2, 2, 2}},
               {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}},
               {"points",
                {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {10, 10, 0}, {0, 0, 10}, {10, 0, 10}, {0, 10, 10}, {10, 10, 10}}}}},
             {"material", material}}}}};
}

std::vector<float> at(const Scene& scene, Vec3 uvw) {
  std::vector<float> f(static_cast<std::size_t>(scene.num_materials()));
  scene.cells.at(0).material->evaluate(uvw, {}, f);
  return f;
}

void expect_near(const std::vector<float>& got, const std::vector<float>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-6f) << "fraction " << i;
}

// Two samples along x, bytes 0 and 255, as a raw file in `dir`.
void write_raw(const std::filesystem::path& dir) { test::write_file(dir / "ramp.raw", std::string("\x00\xff", 2)); }

TEST(SceneTextures, RawPngAndChannels) {
  const auto dir = test::scratch_dir();
  write_raw(dir);
  ordered_json raw = {{"kind", "texture"},
                      {"image", {{"raw", "ramp.raw"}, {"size", {2, 1, 1}}, {"type", "uint8"}}},
                      {"filter", "nearest"},
                      {"channels", {"B"}}};
  const Scene a = parse_scene(scene_with(raw).dump(), dir / "scene.json");
  expect_near(at(a, {0.25, 0.5, 0.5}), {0.0f, 0.0f});
  expect_near(at(a, {0.75, 0.5, 0.5}), {0.0f, 1.0f});
  raw["filter"] = "trilinear";
  expect_near(at(parse_scene(scene_with(raw).dump(), dir / "scene.json"), {0.5, 0.5, 0.5}), {0.0f, 0.5f});

  // A stack of two 1 x 1 PNG slices: red/green channels are A/B; slice 0 below w = 1/2.
  write_png_rgba(dir / "z0.png", 1, 1, std::vector<std::uint8_t>{255, 0, 0, 255});
  write_png_rgba(dir / "z1.png", 1, 1, std::vector<std::uint8_t>{51, 204, 0, 255});
  const ordered_json png = {
      {"kind", "texture"}, {"image", {{"png", {"z0.png", "z1.png"}}}}, {"filter", "nearest"}, {"channels", {"A", "B"}}};
  const Scene b = parse_scene(scene_with(png).dump(), dir / "scene.json");
  expect_near(at(b, {0.5, 0.5, 0.25}), {1.0f, 0.0f});
  expect_near(at(b, {0.5, 0.5, 0.75}), {0.2f, 0.8f});

  // One PNG: a 2D texture over (u, v), the same at every w.
  const ordered_json flat = {{"kind", "texture"},
                             {"image", {{"png", "z1.png"}}},
                             {"wrap", "repeat"},
                             {"repeats", 3},
                             {"channels", {"A", "B"}}};
  const Scene c = parse_scene(scene_with(flat).dump(), dir / "scene.json");
  for (double w : {0.0, 0.5, 1.0}) expect_near(at(c, {0.3, 0.7, w}), {0.2f, 0.8f});
}

TEST(SceneTextures, Errors) {
  const auto dir = test::scratch_dir();
  write_raw(dir);
  const auto error = [&](const ordered_json& material, const std::string& pointer, const std::string& fragment) {
    expect_scene_error(scene_with(material).dump(), pointer, fragment, dir);
  };
  ordered_json t = {{"kind", "texture"}, {"image", {{"raw", "none.raw"}, {"size", {2, 1, 1}}}}, {"channels", {"A"}}};
  error(t, "/cells/0/material/image/raw", "there is no file");
  t["image"] = {{"raw", "ramp.raw"}, {"size", {3, 1, 1}}};
  error(t, "/cells/0/material/image/raw", "holds 2 bytes");
  t["image"] = {{"raw", "ramp.raw"}, {"png", "x.png"}, {"size", {2, 1, 1}}};
  error(t, "/cells/0/material/image", "exactly one of");
  t["image"] = {{"raw", "ramp.raw"}, {"size", {2, 1, 1}}};
  t["wrap"] = "tile";
  error(t, "/cells/0/material/wrap", "\"clamp\", \"repeat\" or \"mirror\"");
  t.erase("wrap");
  t["channels"] = {"C"};
  error(t, "/cells/0/material/channels/0", "unknown material \"C\"");
  t["channels"] = {"A", "B"};
  error(t, "/cells/0/material/channels", "got 2");  // the image has one channel
  t["channels"] = {"A"};
  t["repeats"] = {1, 0, 1};
  error(t, "/cells/0/material/repeats", "repeats[1]");
}

TEST(SceneComposition, EveryRuleFromTheSceneFile) {
  const auto dir = test::scratch_dir();
  write_raw(dir);
  const ordered_json a_only = {{"kind", "constant"}, {"fractions", {{"A", 1}}}};
  const ordered_json b_half = {{"kind", "constant"}, {"fractions", {{"B", 0.5}}}};
  const ordered_json field2 = {
      {"orders", {2, 1, 1}}, {"knots", {{0, 0, 1, 1}, {0, 1}, {0, 1}}}, {"points", {{1, 0}, {0, 1}}}};

  // blend: weight = component 1 of a vector field, linear in u.
  const Scene blend = parse_scene(
      scene_with({{"kind", "blend"}, {"a", "A"}, {"b", b_half}, {"weight", {{"field", field2}, {"component", 1}}}})
          .dump(),
      dir / "s.json");
  expect_near(at(blend, {0.25, 0, 0}), {0.75f, 0.125f});

  // transfer from the magnitude of a vector field: |(3u, 4u)| = 5u.
  const ordered_json field34 = {
      {"orders", {2, 1, 1}}, {"knots", {{0, 0, 1, 1}, {0, 1}, {0, 1}}}, {"points", {{0, 0}, {3, 4}}}};
  const Scene magnitude = parse_scene(
      scene_with({{"kind", "transfer"},
                  {"source", {{"field", field34}, {"magnitude", true}}},
                  {"stops", {{{"value", 0}, {"fractions", {{"A", 1}}}}, {{"value", 5}, {"fractions", {{"B", 1}}}}}}})
          .dump(),
      dir / "s.json");
  expect_near(at(magnitude, {0.2, 0, 0}), {0.8f, 0.2f});

  // transfer: an expression through two stops.
  const Scene transfer = parse_scene(
      scene_with({{"kind", "transfer"},
                  {"source", "2 * v"},
                  {"stops", {{{"value", 0}, {"fractions", {{"A", 1}}}}, {{"value", 1}, {"fractions", {{"B", 1}}}}}}})
          .dump(),
      dir / "s.json");
  expect_near(at(transfer, {0, 0.25, 0}), {0.5f, 0.5f});
  expect_near(at(transfer, {0, 0.75, 0}), {0.0f, 1.0f});

  // threshold on a texture channel (0 at u < 1/2, 1 above, nearest).
  const Scene threshold = parse_scene(
      scene_with({{"kind", "threshold"},
                  {"source", {{"texture", {{"raw", "ramp.raw"}, {"size", {2, 1, 1}}}}, {"filter", "nearest"}}},
                  {"level", 0.5},
                  {"below", a_only},
                  {"above", "B"}})
          .dump(),
      dir / "s.json");
  expect_near(at(threshold, {0.2, 0.5, 0.5}), {1.0f, 0.0f});
  expect_near(at(threshold, {0.8, 0.5, 0.5}), {0.0f, 1.0f});

  // select by region, with void outside.
  const Scene select =
      parse_scene(scene_with({{"kind", "select"},
                              {"regions", {{{"box", {{"lo", {0, 0, 0}}, {"hi", {0.5, 1, 1}}}}, {"material", "A"}}}},
                              {"otherwise", "void"}})
                      .dump(),
                  dir / "s.json");
  expect_near(at(select, {0.4, 0.9, 0.9}), {1.0f, 0.0f});
  expect_near(at(select, {0.6, 0.9, 0.9}), {0.0f, 0.0f});

  // void mask: porosity from an expression.
  const Scene mask =
      parse_scene(scene_with({{"kind", "void_mask"}, {"material", "B"}, {"void", "w"}}).dump(), dir / "s.json");
  expect_near(at(mask, {0, 0, 0.25}), {0.0f, 0.75f});

  // Nesting: a blend of a texture and a select.
  const Scene nested =
      parse_scene(scene_with({{"kind", "blend"},
                              {"a",
                               {{"kind", "texture"},
                                {"image", {{"raw", "ramp.raw"}, {"size", {2, 1, 1}}}},
                                {"filter", "nearest"},
                                {"channels", {"A"}}}},
                              {"b",
                               {{"kind", "select"},
                                {"regions", {{{"box", {{"lo", {0, 0, 0}}, {"hi", {0.5, 1, 1}}}}, {"material", "A"}}}},
                                {"otherwise", "B"}}},
                              {"weight", 0.5}})
                      .dump(),
                  dir / "s.json");
  expect_near(at(nested, {0.8, 0, 0}), {0.5f, 0.5f});
}

TEST(SceneComposition, Errors) {
  const auto error = [&](const ordered_json& material, const std::string& pointer, const std::string& fragment) {
    expect_scene_error(scene_with(material).dump(), pointer, fragment);
  };
  error({{"kind", "blend"}, {"a", "A"}, {"b", "B"}}, "/cells/0/material", "\"weight\" is missing");
  error({{"kind", "blend"}, {"a", "A"}, {"b", "B"}, {"weight", "u +* 2"}}, "/cells/0/material/weight", "u +* 2");
  error({{"kind", "blend"}, {"a", "A"}, {"b", "C"}, {"weight", 0.5}}, "/cells/0/material/b", "unknown material \"C\"");
  error({{"kind", "blend"}, {"a", "A"}, {"b", "B"}, {"weight", true}}, "/cells/0/material/weight", "expected a scalar");
  error({{"kind", "select"},
         {"regions", {{{"box", {{"lo", {0, 0.6, 0}}, {"hi", {1, 0.5, 1}}}}, {"material", "A"}}}},
         {"otherwise", "B"}},
        "/cells/0/material/regions/0/box", "lo[1] = 0.6 is above hi[1] = 0.5");
  error({{"kind", "transfer"},
         {"source", "u"},
         {"stops", {{{"value", 1}, {"fractions", {{"A", 1}}}}, {{"value", 0}, {"fractions", {{"B", 1}}}}}}},
        "/cells/0/material/stops/1/value", "must not decrease");
  error({{"kind", "threshold"},
         {"source",
          {{"field", {{"orders", {1, 1, 1}}, {"knots", {{0, 1}, {0, 1}, {0, 1}}}, {"points", {{0.5, 0.5}}}}},
           {"component", 2}}},
         {"level", 0.5},
         {"below", "A"},
         {"above", "B"}},
        "/cells/0/material/source/component", "outside [0, 1]");
  error({{"kind", "blend"},
         {"a", "A"},
         {"b", "B"},
         {"weight",
          {{"field", {{"orders", {1, 1, 1}}, {"knots", {{0, 1}, {0, 1}, {0, 1}}}, {"points", {0.5}}}},
           {"component", 0},
           {"magnitude", true}}}},
        "/cells/0/material/weight/magnitude", "not both");
}

// An analysis result from a file: IRIT's scalar trivariate sphere16.itd (values from 0 at one
// corner of its domain to 1 at the opposite one) through a transfer function.
TEST(SceneComposition, SharedScalarFieldThroughATransferFunction) {
  const auto file = test::shared_data_dir() / "volumes" / "irit" / "sphere16.itd";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared data absent: " << file;
  const Scene s = parse_scene(
      scene_with({{"kind", "transfer"},
                  {"source", {{"field", {{"file", file.string()}}}}},
                  {"stops", {{{"value", 0}, {"fractions", {{"A", 1}}}}, {{"value", 1}, {"fractions", {{"B", 1}}}}}}})
          .dump(),
      "s.json");
  const std::vector<float> lo = at(s, {0, 0, 0}), hi = at(s, {1, 1, 1});
  EXPECT_NEAR(lo[0] + lo[1], 1.0f, 1e-5f);
  EXPECT_GT(lo[0], hi[0]);  // more A at the corner where the field is small
  EXPECT_GT(hi[1], lo[1]);
}

}  // namespace
}  // namespace trivox
