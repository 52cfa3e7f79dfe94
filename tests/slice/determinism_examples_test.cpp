// Every bundled example scene gives the same output bytes for 1, 2 and 8 threads (once with
// 1, twice with 2 and with 8; 16 layers from the middle of each, so that 8 threads running at
// once each have layers to slice), in every output format: the layer formats (Voxel Print,
// bitmaps, legacy BMPs, greyscale PNGs) and the stack formats (multi-page TIFF, OpenVDB,
// GrabCAD package, previews, and the SL1S archive for the scene made for that printer). The scenes of
// examples/shared_scenes/ are built from ../shared and skip when it is absent.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "job/job_fixtures.h"
#include "support/test_support.h"
#include "trivox/job/job.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::folder_bytes;

// One test per example, so that CTest runs them side by side and each has its own time limit.
const std::vector<std::string>& example_scenes() {
  static const std::vector<std::string> names = {
      "boolean_pair",          "box_gradient",           "chalice",
      "column_greyscale_sl1s", "column_scalar_gradient", "cylinder_sector_curves",
      "dithering_skin",        "expression_layers",      "quick_start",
      "texture_composition",   "twisted_column_porous"};
  return names;
}

// Those of examples/shared_scenes/, read from ../shared.
const std::vector<std::string>& shared_example_scenes() {
  static const std::vector<std::string> names = {"bunny_mesh_box", "duck",   "duck_trimmed_box",
                                                 "hex_nut_radial", "teapot", "teapot_trimmed_box"};
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

// The threads that completed layers (the job calls the sink from the worker that finished the
// layer, one call at a time).
class ThreadsSeen final : public ProgressSink {
 public:
  void on_layer_done(int, int) override { ids_.insert(std::this_thread::get_id()); }
  std::size_t count() const { return ids_.size(); }

 private:
  std::set<std::thread::id> ids_;
};

// Layers sliced per example: twice the largest thread count.
constexpr int kLayers = 16;

TEST_P(DeterminismOfExample, IdenticalAcrossThreadCountsAndRepeats) {
  const bool shared = std::find(shared_example_scenes().begin(), shared_example_scenes().end(), GetParam()) !=
                      shared_example_scenes().end();
  if (shared && test::shared_data_dir().empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const fs::path path = fs::path(TRIVOX_EXAMPLES_DIR) / (shared ? "shared_scenes" : "scenes") / (GetParam() + ".json");
  const Scene scene = read_scene(path);
  const Slicer slicer(scene, {});
  const int layers = slicer.layout().num_layers;
  ASSERT_GE(layers, kLayers) << path;
  const int first_layer = layers / 2 - kLayers / 2;
  const bool sl1s = scene.printer.family == "sl1s";
  const int last_layer = first_layer + kLayers - 1;
  std::map<std::string, std::string> first;
  std::size_t max_threads_seen = 0;
  int runs = 0;
  // Once with 1 thread, twice with 2 and twice with 8. TBB runs at most one thread per core
  // unless told otherwise: the limit is raised so that 8 threads run at once on any machine.
  for (const auto& [threads, repeats] : std::vector<std::pair<int, int>>{{1, 1}, {2, 2}, {8, 2}}) {
    const tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                          static_cast<std::size_t>(threads));
    for (int repeat = 0; repeat < repeats; ++repeat) {
      JobParams p;
      p.output_dir = fs::temp_directory_path() / fmt::format("trivox-determinism-{}-{}", ::getpid(), GetParam());
      fs::remove_all(p.output_dir);
      p.first_layer = first_layer;
      p.last_layer = last_layer;
      p.min_layers = 0;
      p.threads = threads;
      p.formats = {"voxelprint", "bitmaps", "legacy", "greyscale", "tiff", "vdb", "gcvf", "preview"};
      if (sl1s) p.formats.push_back("sl1s");
      ThreadsSeen seen;
      run_slice_job(slicer, p, &seen);
      const auto bytes = folder_bytes(p.output_dir);
      fs::remove_all(p.output_dir);
      EXPECT_LE(seen.count(), static_cast<std::size_t>(threads));
      if (threads == 8) max_threads_seen = std::max(max_threads_seen, seen.count());
      if (runs++ == 0) {
        first = bytes;
        // Per layer a Voxel Print image, a greyscale image and a bitmap and a BMP per
        // material; the stacks, the four previews, slices.txt, materials.csv and the manifest.
        const std::size_t per_layer = 2 + 2 * scene.materials.size();
        EXPECT_EQ(first.size(), static_cast<std::size_t>(kLayers) * per_layer + 3 + 4 + 3 + (sl1s ? 1 : 0)) << path;
        EXPECT_EQ(first.count("vdb/stack.vdb") + first.count("gcvf/stack.gcvf") + first.count("tiff/stack.tif") +
                      first.count("preview/cut_xz.png") + first.count("legacy/slices.txt"),
                  5u);
      } else {
        EXPECT_EQ(bytes, first) << path << " with " << threads << " threads, repeat " << repeat;
      }
    }
  }
  EXPECT_EQ(runs, 5);
  RecordProperty("threads_seen_with_8", static_cast<int>(max_threads_seen));
  // More threads sliced layers than a 2-core machine has cores.
  EXPECT_GE(max_threads_seen, 3u) << path;
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
