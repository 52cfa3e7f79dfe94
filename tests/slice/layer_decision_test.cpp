// The one pixel decision (src/slice/layer_decision.h): the edge coverage of greyscale layers
// decides its sub-samples with it, the slicer its pixels. Made by the edge coverage's path
// (coverage_decision, decide_points) on the pixel grid itself (k = 1), it must give every
// pixel exactly what the slicer gives it: inside or not, the owning cell, the bits of every
// material fraction and the grey level. Compared on 20 layers of every bundled scene (those
// of examples/shared_scenes/ when ../shared is present), of a box trimmed by each shared mesh
// under both inside rules, and of the trimmed teapot. The slicer's layer is taken without
// anti-aliasing, whose edge pixels are the sub-samples' mean, not a pixel centre's decision.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/mesh_fixtures.h"
#include "slice/coverage.h"
#include "slice/mesh_trim_fixtures.h"
#include "support/test_support.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

constexpr int kLayers = 20;

// The scene of `text` (read from `path`) with anti-aliasing off, so that its grey layer is
// every pixel centre's decision.
Scene without_antialiasing(const std::string& text, const fs::path& path) {
  nlohmann::json j = nlohmann::json::parse(text);
  if (j.contains("greyscale")) j["greyscale"]["antialiasing"] = 1;
  return parse_scene(j.dump(), path);
}

Scene read_without_antialiasing(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return without_antialiasing(text.str(), path);
}

// Mismatching pixels of one layer, the first few reported.
int compare_layer(const Slicer& slicer, const detail::LayerDecision& decision, int layer, const std::string& what,
                  std::int64_t& inside_pixels) {
  const SliceLayout& L = slicer.layout();
  const Scene& scene = slicer.scene();
  const int m = scene.num_materials();
  const auto width = static_cast<std::size_t>(L.width_px);
  const std::size_t pixels = width * static_cast<std::size_t>(L.height_px);
  const LayerResult r = slicer.slice_layer(layer, {.owner = true, .rasters = true});
  inside_pixels += r.stats.pixels_inside;
  detail::DecidedPoints points;
  detail::decide_points(
      decision, L.z_of_layer(layer), nullptr, pixels, m,
      [&](int col, int row) { return static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col); }, points);
  // The decision's grid and grey layer, as the slicer makes them from its own.
  MaterialGrid grid(L.width_px, L.height_px, m);
  for (int row = 0; row < L.height_px; ++row)
    std::copy_n(points.fractions.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(row) * width * m),
                width * static_cast<std::size_t>(m), grid.row(row).begin());
  GreyImage grey;
  if (scene.greyscale) {
    const std::vector<std::pair<int, int>> every_column(static_cast<std::size_t>(L.height_px), {0, L.width_px - 1});
    grey = detail::grey_from_grid(grid, every_column, *scene.greyscale, points.grey_source);
  }
  int mismatches = 0;
  for (std::size_t at = 0; at < pixels; ++at) {
    const bool inside = points.owner[at] >= 0;
    bool same = inside == (r.rasters.inside.values()[at] != 0) && points.owner[at] == r.owner[at];
    for (std::size_t j = 0; j < static_cast<std::size_t>(m); ++j) {
      const std::size_t f = at * static_cast<std::size_t>(m) + j;
      same = same && std::bit_cast<std::uint32_t>(grid.values()[f]) ==
                         std::bit_cast<std::uint32_t>(r.rasters.fractions.values()[f]);
    }
    if (scene.greyscale) same = same && grey.values()[at] == r.grey.values()[at];
    if (!same && ++mismatches <= 5)
      ADD_FAILURE() << what << ": layer " << layer << " pixel " << at % width << ", " << at / width
                    << ": the decision at k = 1 gives owner " << points.owner[at] << ", the slicer " << r.owner[at];
  }
  return mismatches;
}

// Compares kLayers layers spread over the scene; returns the pixels compared inside a cell.
std::int64_t expect_same_decision(const Scene& scene, const std::string& what) {
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const auto decision = detail::coverage_decision(scene, slicer.params(), L);
  int mismatches = 0;
  std::int64_t inside = 0;
  for (int i = 0; i < kLayers && i < L.num_layers; ++i) {
    const int layer = (2 * i + 1) * L.num_layers / (2 * kLayers);
    mismatches += compare_layer(slicer, *decision, layer, what, inside);
  }
  EXPECT_EQ(mismatches, 0) << what;
  return inside;
}

class LayerDecisionOfExample : public ::testing::TestWithParam<std::string> {};

TEST_P(LayerDecisionOfExample, CoveragePathAtPixelCentresIsTheSlicers) {
  const std::string& name = GetParam();
  const bool shared = name.starts_with("shared_scenes/");
  if (shared && test::shared_data_dir().empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Scene scene = read_without_antialiasing(fs::path(TRIVOX_EXAMPLES_DIR) / (name + ".json"));
  EXPECT_GT(expect_same_decision(scene, name), 0) << name << ": no pixel inside a cell";
}

std::vector<std::string> bundled_scenes() {
  std::vector<std::string> names;
  for (const char* folder : {"scenes", "shared_scenes"})
    for (const auto& entry : fs::directory_iterator(fs::path(TRIVOX_EXAMPLES_DIR) / folder))
      if (entry.path().extension() == ".json")
        names.push_back(std::string(folder) + "/" + entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

INSTANTIATE_TEST_SUITE_P(Bundled, LayerDecisionOfExample, ::testing::ValuesIn(bundled_scenes()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           std::string n = param.param;
                           for (char& c : n)
                             if (c == '/') c = '_';
                           return n;
                         });

TEST(LayerDecision, CoveragePathAtPixelCentresIsTheSlicersForEveryMeshTrimAndRule) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  for (const test::SharedMesh& mesh : test::kMeshes) {
    const fs::path path = dir / "meshes" / mesh.name;
    const Box3 box = test::cell_box(test::placed(test::read_stl_soup(path), mesh.scale));
    for (const std::string rule : {"even-odd", "winding-number"}) {
      const std::string what = fmt::format("{} ({})", mesh.name, rule);
      const Scene scene = parse_scene(test::scene_json(path, mesh.scale, box, rule), "mesh_trim.json");
      EXPECT_GT(expect_same_decision(scene, what), 0) << what;
    }
  }
}

}  // namespace
}  // namespace trivox
