// GoTools .g2 files in scenes: a cell's geometry from a .g2 volume and a trimming shell from
// .g2 surfaces, wherever the scene takes model files. The duck-trimmed box, its box and duck
// written as .g2, slices to the same labels as from the inline box and the G+Smo duck.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "support/test_support.h"
#include "trivox/io/model.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

std::string scene_text(const std::string& geometry, const std::string& shell_file) {
  return fmt::format(R"({{
  "version": 1, "units": "mm",
  "printer": {{ "base": "j750-hq", "x_dpi": 100, "y_dpi": 100, "layer_thickness_mm": 0.5 }},
  "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [{{
    "name": "duck body",
    "geometry": {},
    "trim": [{{ "side": "inside", "shell": {{ "file": "{}", "placement": {{ "scale": 10 }} }} }}],
    "material": {{ "kind": "expression", "fractions": {{ "VeroCyan": "w", "VeroMagenta": "1 - w" }} }}
  }}]
}})",
                     geometry, shell_file);
}

constexpr const char* kInlineBox = R"({ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
      "points": [[-8, -13, -7], [9, -13, -7], [-8, 7, -7], [9, 7, -7], [-8, -13, 3], [9, -13, 3], [-8, 7, 3], [9, 7, 3]] })";

constexpr const char* kBoxG2 =
    "700 1 0 0\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n"
    "-8 -13 -7\n9 -13 -7\n-8 7 -7\n9 7 -7\n-8 -13 3\n9 -13 3\n-8 7 3\n9 7 3\n";

TEST(SceneG2, VolumeAndTrimmingShellFromG2SliceAsFromTheOtherFormats) {
  const fs::path data = test::shared_data_dir();
  if (data.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  test::ScratchDir dir;
  const Model duck = read_model(data / "surfaces/duck_brep.xml");
  {
    std::ofstream out(dir.path() / "duck.g2");
    write_g2(out, duck);
    std::ofstream(dir.path() / "box.g2") << kBoxG2;
  }
  const Scene from_g2 = parse_scene(scene_text(R"({ "file": "box.g2" })", "duck.g2"), dir.path() / "scene.json");
  const Scene reference =
      parse_scene(scene_text(kInlineBox, (data / "surfaces/duck_brep.xml").string()), dir.path() / "reference.json");
  ASSERT_EQ(from_g2.cells.size(), 1u);
  ASSERT_EQ(from_g2.cells[0].trim.clauses.size(), 1u);
  EXPECT_EQ(from_g2.input_files.size(), 2u);  // both .g2 files, hashed for the manifest
  const Slicer a(from_g2, {}), b(reference, {});
  ASSERT_EQ(a.layout().num_layers, b.layout().num_layers);
  ASSERT_EQ(a.layout().width_px, b.layout().width_px);
  std::int64_t inside = 0;
  for (int layer = 2; layer < a.layout().num_layers; layer += 8) {
    const LayerResult ra = a.slice_layer(layer), rb = b.slice_layer(layer);
    EXPECT_TRUE(std::equal(ra.labels.values().begin(), ra.labels.values().end(), rb.labels.values().begin(),
                           rb.labels.values().end()))
        << "layer " << layer;
    inside += ra.stats.pixels_inside;
  }
  EXPECT_GT(inside, 1000);  // the shell trims, and keeps something
}

}  // namespace
}  // namespace trivox
