// An empty result is not success (docs/CLI.md, exit code 6): a job whose bitmap is under 2
// pixels along x or y (a 4 nm box, 8 identical control points) is refused before anything is
// written, and one that slices every layer without a voxel inside the object (a sheet of no
// thickness, which falls between the pixel centres) ends with exit 6 after writing its files;
// --allow-empty accepts both. A model 1e17 mm from the origin is refused earlier, as an input
// error (the precision check).
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// One trilinear cell with these eight corners (u fastest), constant VeroCyan; `extra` goes
// into the cell.
std::string cell_scene(const std::vector<std::array<double, 3>>& corners, const std::string& extra = "") {
  std::string points;
  for (const auto& p : corners) points += fmt::format("{}[{}, {}, {}]", points.empty() ? "" : ", ", p[0], p[1], p[2]);
  return fmt::format(R"({{"version": 1, "units": "mm", "printer": "j750-hm", "materials": [{{"name": "VeroCyan"}}],
 "cells": [{{"name": "c", "geometry": {{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [{}]}}{}, "material": {{"kind": "constant", "fractions": {{"VeroCyan": 1}}}}}}]}})",
                     points, extra);
}

std::vector<std::array<double, 3>> box_corners(double size_mm) {
  std::vector<std::array<double, 3>> corners;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) corners.push_back({size_mm * i, size_mm * j, size_mm * k});
  return corners;
}

CliResult slice(const fs::path& scene, const fs::path& out, const std::string& options = "") {
  return run_cli(fmt::format("slice {} -o {} -q {}", shell_quote(scene), shell_quote(out), options));
}

TEST(CliEmptyResult, AnObjectSmallerThanTwoPixelsIsRefusedBeforeAnythingIsWritten) {
  const struct {
    const char* name;
    std::string scene;
  } cases[] = {{"4nm.json", cell_scene(box_corners(4e-6))}, {"4um.json", cell_scene(box_corners(4e-3))}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    ScratchDir dir;
    write_text(dir.path() / c.name, c.scene);
    const CliResult r = slice(dir.path() / c.name, dir.path() / "out");
    EXPECT_EQ(r.exit_code, 6) << r.err;
    EXPECT_NE(r.err.find(fmt::format("{}: the object is 1 x 1 px at printer 'j750-hm'", c.name)), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("a bitmap under 2 pixels along x or y cannot show it"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "out"));
    const CliResult checked = run_cli("validate " + shell_quote(dir.path() / c.name));
    EXPECT_EQ(checked.exit_code, 6) << checked.err;
    const CliResult allowed = slice(dir.path() / c.name, dir.path() / "out", "--allow-empty");
    EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
    EXPECT_TRUE(fs::exists(dir.path() / "out" / "slice_00001.png"));
  }
}

TEST(CliEmptyResult, AStackWithoutAVoxelOfTheObjectEndsWithExitSixAfterWritingIt) {
  ScratchDir dir;
  // A slanted slab a nanometre thick: the bitmap is 95 x 18 px, but no pixel centre lies in it.
  std::vector<std::array<double, 3>> sheet;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) sheet.push_back({4.0 * i, 1.48 * i + 0.0123 + 1e-6 * j, 4.0 * k});
  write_text(dir.path() / "sheet.json", cell_scene(sheet));
  const fs::path out = dir.path() / "out";
  const CliResult r = slice(dir.path() / "sheet.json", out, "--layers 1:3 --min-layers 0");
  EXPECT_EQ(r.exit_code, 6) << r.err;
  EXPECT_NE(r.err.find(out.string() + ": the stack holds no voxel of the object: no pixel centre of its 3 layers"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("voxels inside: 0,"), std::string::npos) << r.out;
  // The summary names the model's layers the job covers, numbered as --layers numbers them.
  EXPECT_NE(r.out.find("sliced 3 layers (95 x 18 px, layers 1 to 3 of the model's 149) into"), std::string::npos)
      << r.out;
  // The files are whole and listed: the job itself is complete.
  EXPECT_EQ(nlohmann::json::parse(read_text(out / "manifest.json")).at("status"), "complete");
  EXPECT_EQ(run_cli("verify " + shell_quote(out)).exit_code, 0);
  const CliResult allowed =
      slice(dir.path() / "sheet.json", dir.path() / "allowed", "--layers 1:3 --min-layers 0 --allow-empty");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_NE(allowed.out.find("note: the stack holds no voxel of the object (--allow-empty)"), std::string::npos)
      << allowed.out;
  // Layers of one shard, or those a resumed run finds done, are not the whole job: no verdict.
  const CliResult shard =
      slice(dir.path() / "sheet.json", dir.path() / "shard", "--layers 1:3 --min-layers 0 --shard 1/2");
  EXPECT_EQ(shard.exit_code, 0) << shard.err;
}

// Coinciding control points leave a cell without interior: an input error, named when the
// scene is read (no --allow-empty accepts it).
TEST(CliEmptyResult, ACellWhoseControlPointsCoincideIsAnInputError) {
  ScratchDir dir;
  write_text(dir.path() / "same.json", cell_scene(std::vector<std::array<double, 3>>(8, {1, 2, 3})));
  for (const char* options : {"", "--allow-empty"}) {
    const CliResult r = slice(dir.path() / "same.json", dir.path() / "out", options);
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("cell 'c' has no interior"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "out"));
  }
}

TEST(CliEmptyResult, AModelFarFromTheOriginIsAnInputErrorFirst) {
  ScratchDir dir;
  write_text(dir.path() / "far.json", cell_scene(box_corners(4), R"(, "placement": {"translate": [1e17, 0, 0]})"));
  const CliResult r = slice(dir.path() / "far.json", dir.path() / "out");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("from the origin, where a double resolves only"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

}  // namespace
}  // namespace trivox::test
