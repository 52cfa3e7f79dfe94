// Every bundled example scene gives the same output bytes for 1, 2 and 8 threads, three
// times each (two layers from the middle of each, to keep the suite quick), in the layer
// formats and in the stack formats (multi-page TIFF, OpenVDB, GrabCAD package). The scenes
// of examples/shared_scenes/ are built from ../shared and skip when it is absent.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/job.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

std::map<std::string, std::string> folder_bytes(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().lexically_relative(dir).generic_string();
    if (name == "stats.json") continue;  // timings
    std::ifstream in(e.path(), std::ios::binary);
    out[name] = {std::istreambuf_iterator<char>(in), {}};
  }
  return out;
}

// One test per example, so that CTest runs them side by side and each has its own time limit.
const std::vector<std::string>& example_scenes() {
  static const std::vector<std::string> names = {
      "boolean_pair", "box_gradient", "chalice", "column_scalar_gradient", "cylinder_sector_curves",
      "dithering_skin", "expression_layers", "quick_start", "texture_composition",
      "twisted_column_porous"};
  return names;
}

// Those of examples/shared_scenes/, read from ../shared.
const std::vector<std::string>& shared_example_scenes() {
  static const std::vector<std::string> names = {"duck", "duck_trimmed_box", "teapot", "teapot_trimmed_box"};
  return names;
}

std::vector<std::string> scenes_in(const char* folder) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(fs::path(TRIVOX_EXAMPLES_DIR) / folder))
    if (entry.path().extension() == ".json") found.push_back(entry.path().stem().string());
  std::sort(found.begin(), found.end());
  return found;
}

TEST(Determinism, EveryExampleSceneIsListed) {
  EXPECT_EQ(scenes_in("scenes"), example_scenes());
  EXPECT_EQ(scenes_in("shared_scenes"), shared_example_scenes());
}

class DeterminismOfExample : public ::testing::TestWithParam<std::string> {};

TEST_P(DeterminismOfExample, IdenticalAcrossThreadCountsAndRepeats) {
  const bool shared = std::find(shared_example_scenes().begin(), shared_example_scenes().end(), GetParam()) !=
                      shared_example_scenes().end();
  if (shared && test::shared_data_dir().empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const fs::path path = fs::path(TRIVOX_EXAMPLES_DIR) / (shared ? "shared_scenes" : "scenes") / (GetParam() + ".json");
  const Scene scene = read_scene(path);
  const Slicer slicer(scene, {});
  const int middle = slicer.layout().num_layers / 2;
  std::map<std::string, std::string> first;
  int runs = 0;
  for (int threads : {1, 2, 8}) {
    for (int repeat = 0; repeat < 3; ++repeat) {
      JobParams p;
      p.output_dir = fs::temp_directory_path() / fmt::format("trivox-determinism-{}-{}", ::getpid(), GetParam());
      fs::remove_all(p.output_dir);
      p.first_layer = std::max(0, middle - 1);
      p.last_layer = middle;
      p.min_layers = 0;
      p.threads = threads;
      p.formats = {"voxelprint", "bitmaps", "tiff", "vdb", "gcvf"};
      run_slice_job(slicer, p);
      const auto bytes = folder_bytes(p.output_dir);
      fs::remove_all(p.output_dir);
      if (runs++ == 0) {
        first = bytes;
        EXPECT_GE(first.size(), 6u) << path;  // two layers, the manifest and the three stacks at least
        EXPECT_EQ(first.count("vdb/stack.vdb") + first.count("gcvf/stack.gcvf") + first.count("tiff/stack.tif"), 3u);
      } else {
        EXPECT_EQ(bytes, first) << path << " with " << threads << " threads, repeat " << repeat;
      }
    }
  }
  EXPECT_EQ(runs, 9);
}

std::vector<std::string> all_example_scenes() {
  std::vector<std::string> all = example_scenes();
  all.insert(all.end(), shared_example_scenes().begin(), shared_example_scenes().end());
  return all;
}

INSTANTIATE_TEST_SUITE_P(Examples, DeterminismOfExample, ::testing::ValuesIn(all_example_scenes()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace trivox
