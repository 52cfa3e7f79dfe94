// The scene reader: a minimal scene, and every rule it enforces failing with an InputError
// that names the scene file and the JSON pointer of the field.
#include <atomic>
#include <cmath>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scene/scene_test_util.h"
#include "trivox/error.h"
#include "trivox/printer/material_library.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
using test::expect_scene_error;

ordered_json unit_box(double size) {
  ordered_json points = ordered_json::array();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) points.push_back({i * size, j * size, k * size});
  return {{"orders", {2, 2, 2}}, {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}}, {"points", points}};
}

ordered_json minimal_scene() {
  return {
      {"units", "mm"},
      {"printer", "j750-paper"},
      {"materials", {{{"name", "A"}, {"rgba", {255, 0, 0, 255}}}, {{"name", "B"}, {"rgba", "#00ff0080"}}}},
      {"cells",
       {{{"geometry", unit_box(10)}, {"material", {{"kind", "constant"}, {"fractions", {{"A", 0.25}, {"B", 0.5}}}}}}}}};
}

TEST(SceneReader, MinimalScene) {
  const Scene scene = parse_scene(minimal_scene().dump(), "dir/min.json");
  EXPECT_EQ(scene.source, "dir/min.json");
  EXPECT_EQ(scene.printer.name, "j750-paper");
  EXPECT_EQ(scene.printer.x_dpi, 600.0);
  EXPECT_EQ(scene.printer.y_dpi, 300.0);
  EXPECT_EQ(scene.printer.layer_thickness_mm, 0.030);
  ASSERT_EQ(scene.num_materials(), 2);
  EXPECT_EQ(scene.materials[0].name, "A");
  EXPECT_EQ(scene.materials[1].rgba, (std::array<std::uint8_t, 4>{0, 255, 0, 128}));
  EXPECT_EQ(scene.material_index("B"), 1);
  EXPECT_EQ(scene.material_index("void"), kVoidMaterial);
  EXPECT_EQ(scene.fraction_policy.policy, SumPolicy::kError);
  ASSERT_EQ(scene.cells.size(), 1u);
  const Cell& cell = scene.cells[0];
  EXPECT_EQ(cell.name, "cell 0");
  EXPECT_EQ(cell.pointer, "/cells/0");
  EXPECT_EQ(cell.volume.evaluate({1, 1, 1}), (Vec3{10, 10, 10}));
  std::vector<float> f(2);
  cell.material->evaluate({0.5, 0.5, 0.5}, {5, 5, 5}, f);
  EXPECT_EQ(f, (std::vector<float>{0.25f, 0.5f}));
  EXPECT_EQ(scene.bounds().hi, (Vec3{10, 10, 10}));
}

// A raised stop flag (the program's SIGINT or SIGTERM) stops the reading at the next cell.
TEST(SceneReader, AStopFlagStopsTheReadingAtTheNextCell) {
  std::atomic<bool> stop{true};
  EXPECT_THROW((void)parse_scene(minimal_scene().dump(), "dir/min.json", &stop), CancelledError);
  stop = false;
  EXPECT_EQ(parse_scene(minimal_scene().dump(), "dir/min.json", &stop).cells.size(), 1u);
}

TEST(SceneReader, DitheringSettings) {
  auto j = minimal_scene();
  EXPECT_FALSE(parse_scene(j.dump(), "s.json").dithering.has_value());
  j["dithering"] = {
      {"method", "jarvis-judice-ninke"}, {"serpentine", false}, {"vary_by_layer", false}, {"skin_voxels", 3}};
  const Scene scene = parse_scene(j.dump(), "s.json");
  ASSERT_TRUE(scene.dithering.has_value());
  EXPECT_EQ(scene.dithering->method, DitherMethod::kErrorDiffusion);
  EXPECT_EQ(scene.dithering->kernel, DiffusionKernel::kJarvisJudiceNinke);
  EXPECT_FALSE(scene.dithering->serpentine);
  EXPECT_FALSE(scene.dithering->vary_by_layer);
  EXPECT_EQ(scene.dithering->skin_voxels, 3);
  j["dithering"] = {{"method", "blue-noise"}};
  EXPECT_EQ(parse_scene(j.dump(), "s.json").dithering->method, DitherMethod::kBlueNoise);

  j["dithering"] = {{"method", "ordered"}};
  test::expect_scene_error(j.dump(), "/dithering/method", "unknown dithering method \"ordered\"");
  j["dithering"] = {{"skin_voxels", -1}};
  test::expect_scene_error(j.dump(), "/dithering/skin_voxels", "-1");
  j["dithering"] = {{"kernel", "stucki"}};
  test::expect_scene_error(j.dump(), "/dithering/kernel", "unknown key");
}

// Materials may be named from the printer library: a plain name, or an object without a
// colour; a cell's material may be a plain material name.
TEST(SceneReader, LibraryMaterials) {
  auto j = minimal_scene();
  j["materials"] = {"VeroCyan", {{"name", "agilus30 black"}}, {{"name", "VeroMagenta"}, {"rgba", "#102030"}}};
  j["cells"][0]["material"] = "VeroMagenta";
  const Scene scene = parse_scene(j.dump(), "s.json");
  ASSERT_EQ(scene.num_materials(), 3);
  EXPECT_EQ(scene.materials[0].name, "VeroCyan");
  EXPECT_EQ(scene.materials[0].library, "VeroCyan");
  EXPECT_EQ(scene.materials[0].rgba, find_library_material("VeroCyan")->rgba);
  EXPECT_EQ(scene.materials[1].name, "agilus30 black");  // an object keeps its own spelling
  EXPECT_EQ(scene.materials[1].library, "Agilus30Black");
  EXPECT_EQ(scene.materials[1].rgba, find_library_material("Agilus30Black")->rgba);
  EXPECT_EQ(scene.materials[2].rgba, (std::array<std::uint8_t, 4>{0x10, 0x20, 0x30, 255}));  // given colour wins
  EXPECT_EQ(scene.materials[2].library, "VeroMagenta");
  std::vector<float> f(3);
  scene.cells[0].material->evaluate({0.5, 0.5, 0.5}, {5, 5, 5}, f);
  EXPECT_EQ(f, (std::vector<float>{0.0f, 0.0f, 1.0f}));

  j["materials"] = {"VeroCyan", "Unobtainium"};
  j["cells"][0]["material"] = "VeroCyan";
  test::expect_scene_error(j.dump(), "/materials/1", "not a library material");
  j["materials"] = {"VeroCyan"};
  j["cells"][0]["material"] = "VeroYellow";
  test::expect_scene_error(j.dump(), "/cells/0/material", "unknown material \"VeroYellow\"");
}

TEST(SceneReader, PrinterProfiles) {
  ordered_json s = minimal_scene();
  s["printer"] = "J750-HQ";  // case-insensitive
  EXPECT_EQ(parse_scene(s.dump(), "s.json").printer.layer_thickness_mm, 0.014);
  s["printer"] = {{"base", "j850-hm"}, {"layer_thickness_mm", 0.02}, {"name", "mine"}};
  PrinterProfile p = parse_scene(s.dump(), "s.json").printer;
  EXPECT_EQ(p.name, "mine");
  EXPECT_EQ(p.layer_thickness_mm, 0.02);
  EXPECT_EQ(p.max_materials, 6);
  s["printer"] = {{"x_dpi", 1200}, {"y_dpi", 600}, {"layer_thickness_mm", 0.016}, {"max_materials", 3}};
  p = parse_scene(s.dump(), "s.json").printer;
  EXPECT_EQ(p.x_dpi, 1200.0);
  EXPECT_EQ(p.max_materials, 3);
}

TEST(SceneErrors, BadPrinter) {
  ordered_json s = minimal_scene();
  s["printer"] = "j999";
  expect_scene_error(s.dump(), "/printer", "j750-hq");  // the message lists the known profiles
  s["printer"] = {{"x_dpi", 600}, {"y_dpi", 300}, {"layer_thickness_mm", 0.03}};
  expect_scene_error(s.dump(), "/printer", "max_materials");
  s["printer"] = {{"base", "j750-hq"}, {"y_dpi", -300}};
  expect_scene_error(s.dump(), "/printer/y_dpi", "not > 0");
  s["printer"] = "j750-hs";  // 3 materials per job
  s["materials"].push_back({{"name", "C"}, {"rgba", {1, 2, 3}}});
  s["materials"].push_back({{"name", "D"}, {"rgba", {1, 2, 3}}});
  expect_scene_error(s.dump(), "/materials", "at most 3");
}

TEST(SceneErrors, UnknownMaterialNameInMaterialFunction) {
  ordered_json s = minimal_scene();
  s["cells"][0]["material"]["fractions"] = {{"A", 0.5}, {"Nope", 0.5}};
  expect_scene_error(s.dump(), "/cells/0/material/fractions/Nope", "unknown material \"Nope\"");
  s["cells"][0]["material"] = {{"kind", "porous_tiles"}, {"tiles", 2}, {"materials", {"A", "Red"}}};
  expect_scene_error(s.dump(), "/cells/0/material/materials/1", "\"A\", \"B\"");
  s["cells"][0]["material"] = {{"kind", "constant"}, {"fractions", {{"void", 0.5}}}};
  expect_scene_error(s.dump(), "/cells/0/material/fractions/void", "implicit");
}

TEST(SceneErrors, MissingModelFile) {
  const auto dir = test::scratch_dir();
  ordered_json s = minimal_scene();
  s["cells"][0]["geometry"] = {{"file", "models/absent.itd"}, {"patch", 0}};
  expect_scene_error(s.dump(), "/cells/0/geometry/file", "absent.itd", dir);
  // A file that is there but is not a model.
  test::write_file(dir / "junk.itd", "this is not IRIT");
  s["cells"][0]["geometry"] = {{"file", "junk.itd"}};
  expect_scene_error(s.dump(), "/cells/0/geometry/file", "junk.itd", dir);
}

TEST(SceneErrors, SumAbovePolicyToleranceFailsOnEvaluation) {
  ordered_json s = minimal_scene();
  s["cells"][0]["name"] = "lid";
  s["cells"][0]["material"]["fractions"] = {{"A", 0.6}, {"B", 0.7}};
  s["fraction_sums"] = {{"policy", "error"}};
  const Scene scene = parse_scene(s.dump(), "s.json");  // reading is fine: rules apply per sample
  std::vector<float> f(2);
  try {
    scene.cells[0].material->evaluate({0.5, 0.25, 1}, {}, f);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.where(), "/cells/0/material");
    EXPECT_NE(what.find("s.json"), std::string::npos) << what;
    EXPECT_NE(what.find("/cells/0/material"), std::string::npos) << what;
    EXPECT_NE(what.find("'lid'"), std::string::npos) << what;
    EXPECT_NE(what.find("1.3"), std::string::npos) << what;
    EXPECT_NE(what.find("(0.5, 0.25, 1)"), std::string::npos) << what;
  }
  s["fraction_sums"] = {{"policy", "normalise"}};
  parse_scene(s.dump(), "s.json").cells[0].material->evaluate({0.5, 0.25, 1}, {}, f);
  EXPECT_NEAR(f[0] + f[1], 1.0, 1e-6);
  EXPECT_NEAR(f[0] / f[1], 0.6 / 0.7, 1e-6);
  s["fraction_sums"] = {{"policy", "ignore"}};
  expect_scene_error(s.dump(), "/fraction_sums/policy", "\"normalise\"");
}

TEST(SceneErrors, UnknownKeys) {
  ordered_json s = minimal_scene();
  s["colour"] = 1;
  expect_scene_error(s.dump(), "/colour", "unknown key \"colour\"");
  s = minimal_scene();
  s["cells"][0]["materail"] = 1;
  expect_scene_error(s.dump(), "/cells/0/materail", "\"material\"");
  s = minimal_scene();
  s["cells"][0]["geometry"]["weight"] = {1};
  expect_scene_error(s.dump(), "/cells/0/geometry/weight", "unknown key");
  s = minimal_scene();
  s["cells"][0]["material"]["radius"] = 1;
  expect_scene_error(s.dump(), "/cells/0/material/radius", "unknown key");
}

TEST(SceneErrors, BadRgba) {
  ordered_json s = minimal_scene();
  s["materials"][0]["rgba"] = {300, 0, 0, 255};
  expect_scene_error(s.dump(), "/materials/0/rgba/0", "outside [0, 255]");
  s["materials"][0]["rgba"] = {0, 0};
  expect_scene_error(s.dump(), "/materials/0/rgba", "3 to 4 elements");
  s["materials"][0]["rgba"] = "#12345";
  expect_scene_error(s.dump(), "/materials/0/rgba", "#RRGGBB");
  s["materials"][0]["rgba"] = {0.5, 0, 0};
  expect_scene_error(s.dump(), "/materials/0/rgba/0", "integer");
}

TEST(SceneErrors, TopLevelRules) {
  ordered_json s = minimal_scene();
  s["units"] = "inch";
  expect_scene_error(s.dump(), "/units", "\"mm\"");
  s = minimal_scene();
  s.erase("cells");
  expect_scene_error(s.dump(), "", "\"cells\" is missing");
  s = minimal_scene();
  s["version"] = 2;
  expect_scene_error(s.dump(), "/version", "version 1");
  s = minimal_scene();
  s["materials"][1]["name"] = "A";
  expect_scene_error(s.dump(), "/materials/1/name", "declared already");
  s["materials"][1]["name"] = "void";
  expect_scene_error(s.dump(), "/materials/1/name", "reserved");
  s = minimal_scene();
  s["cells"].push_back(s["cells"][0]);
  s["cells"][0]["name"] = "x";
  s["cells"][1]["name"] = "x";
  expect_scene_error(s.dump(), "/cells/1/name", "taken by /cells/0");
}

TEST(SceneErrors, JsonSyntaxAndDuplicateKeys) {
  try {
    parse_scene("{\n  \"units\": \"mm\",\n  \"printer\": ,\n}", "bad.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.json:3"), std::string::npos) << e.what();
  }
  std::string text = minimal_scene().dump();
  text.insert(text.find("\"kind\""), "\"kind\":\"constant\",");
  expect_scene_error(text, "/cells/0/material", "appears twice");
}

TEST(SceneErrors, InlineSplineRules) {
  ordered_json s = minimal_scene();
  s["cells"][0]["geometry"]["points"].erase(7);
  expect_scene_error(s.dump(), "/cells/0/geometry/points", "2 x 2 x 2 = 8 control points");
  s = minimal_scene();
  s["cells"][0]["geometry"]["knots"][1] = {0, 1, 0.5, 1};
  expect_scene_error(s.dump(), "/cells/0/geometry/knots/1", "");
  s = minimal_scene();
  s["cells"][0]["geometry"]["points"][3] = {1, 2};
  expect_scene_error(s.dump(), "/cells/0/geometry/points/3", "3 elements");
  s = minimal_scene();
  s["cells"][0]["geometry"]["weights"] = {1, 1, 1, 1, 1, 1, 1, 0};
  expect_scene_error(s.dump(), "/cells/0/geometry/weights/7", "not > 0");
  s = minimal_scene();
  s["cells"][0]["geometry"]["orders"] = {2, 2, 0};
  expect_scene_error(s.dump(), "/cells/0/geometry/orders/2", "outside [1, 32]");
}

TEST(SceneErrors, MaterialFunctionRules) {
  ordered_json s = minimal_scene();
  s["cells"][0]["material"] = {{"kind", "gradient"}};
  expect_scene_error(s.dump(), "/cells/0/material/kind", "\"scalar_gradient\"");
  s["cells"][0]["material"] = {{"kind", "expression"}, {"fractions", {{"A", "u +* 2"}}}};
  expect_scene_error(s.dump(), "/cells/0/material/fractions/A", "u +* 2");
  s["cells"][0]["material"] = {{"kind", "expression"}, {"fractions", {{"A", "k*u"}}}, {"constants", {{"x", 2}}}};
  expect_scene_error(s.dump(), "/cells/0/material/constants", "variables");
  s["cells"][0]["material"] = {
      {"kind", "porous_tiles"}, {"tiles", {2, 2, 2}}, {"radius", 0.7}, {"materials", {"A", "void"}}};
  expect_scene_error(s.dump(), "/cells/0/material/radius", "outside [0, 0.5]");
  s["cells"][0]["material"] = {{"kind", "twisting_curves"}, {"points", {{{"uv", {0.5, 0.5}}, {"material", "A"}}}}};
  expect_scene_error(s.dump(), "/cells/0/material", "\"radius\" is missing");
  s["cells"][0]["material"] = {
      {"kind", "scalar_gradient"},
      {"field", {{"orders", {1, 1, 1}}, {"knots", {{0, 1}, {0, 1}, {0, 1}}}, {"points", {0.5}}}},
      {"stops", {{{"value", 1}, {"fractions", {{"A", 1}}}}, {{"value", 0}, {"fractions", {{"B", 1}}}}}}};
  expect_scene_error(s.dump(), "/cells/0/material/stops/1/value", "must not decrease");
  s["cells"][0]["material"] = {
      {"kind", "spline_field"},
      {"components", {"A", "A"}},
      {"field", {{"orders", {1, 1, 1}}, {"knots", {{0, 1}, {0, 1}, {0, 1}}}, {"points", {{0.5, 0.5}}}}}};
  expect_scene_error(s.dump(), "/cells/0/material/components/1", "component 0 already");
  s["cells"][0]["material"]["components"] = {"A", "B"};
  s["cells"][0]["material"]["field"]["points"] = {{0.5, 0.5, 0.5}};
  expect_scene_error(s.dump(), "/cells/0/material/field/points/0", "2 elements");
}

TEST(SceneReader, EveryMaterialKindBuildsAndEvaluates) {
  ordered_json s = minimal_scene();
  const ordered_json field1 = {
      {"orders", {2, 1, 1}}, {"knots", {{0, 0, 1, 1}, {0, 1}, {0, 1}}}, {"points", {0.0, 1.0}}};
  const ordered_json field2 = {
      {"orders", {2, 1, 1}}, {"knots", {{0, 0, 1, 1}, {0, 1}, {0, 1}}}, {"points", {{1, 0}, {0, 1}}}};
  const std::vector<ordered_json> kinds = {
      {{"kind", "spline_field"}, {"components", {"A", "B"}}, {"field", field2}},
      {{"kind", "scalar_gradient"},
       {"field", field1},
       {"stops", {{{"value", 0}, {"fractions", {{"A", 1}}}}, {{"value", 1}, {"fractions", {{"B", 1}}}}}}},
      {{"kind", "expression"}, {"fractions", {{"A", "1 - u"}, {"B", "u"}}}},
  };
  for (const ordered_json& m : kinds) {
    s["cells"][0]["material"] = m;
    const Scene scene = parse_scene(s.dump(), "s.json");
    std::vector<float> f(2);
    // Every one of these is a linear ramp A -> B along u.
    scene.cells[0].material->evaluate({0.25, 0.5, 0.5}, {2.5, 5, 5}, f);
    EXPECT_NEAR(f[0], 0.75, 1e-6) << m.dump();
    EXPECT_NEAR(f[1], 0.25, 1e-6) << m.dump();
  }
  s["cells"][0]["material"] = {{"kind", "twisting_curves"},
                               {"points", {{{"uv", {0.8, 0.5}}, {"material", "B"}}}},
                               {"radius", 0.05},
                               {"turns_per_w", 1},
                               {"background", "A"},
                               {"wrap", {"u"}}};
  std::vector<float> f(2);
  parse_scene(s.dump(), "s.json").cells[0].material->evaluate({0.5, 0.8, 0.25}, {}, f);
  EXPECT_EQ(f, (std::vector<float>{0.0f, 1.0f}));
  s["cells"][0]["material"] = {
      {"kind", "porous_tiles"}, {"tiles", {2, 2, 2}}, {"materials", {"void", "B"}}, {"cylinder_axes", {"v", "w"}}};
  parse_scene(s.dump(), "s.json").cells[0].material->evaluate({0.55, 0.05, 0.05}, {}, f);  // tile (1,0,0)
  EXPECT_EQ(f, (std::vector<float>{0.0f, 1.0f}));
}

}  // namespace
}  // namespace trivox
