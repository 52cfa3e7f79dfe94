// The bundled models that are built from the real surfaces in ../shared
// (examples/shared_scenes/): they read, no cell folds, and a few layers slice at the
// printer's full resolution without a pixel the global solver left unresolved.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

const fs::path kSharedScenes = fs::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes";

void check_model(const std::string& name, std::size_t cells) {
  const Scene scene = read_scene(kSharedScenes / (name + ".json"));
  ASSERT_EQ(scene.cells.size(), cells);
  for (const Cell& cell : scene.cells) {
    const JacobianReport r = check_jacobian(cell.volume, {17});
    EXPECT_NE(r.classification, JacobianClass::kFolded) << name << ": cell " << cell.name;
  }
  const Slicer slicer(scene, {});
  const int n = slicer.layout().num_layers;
  ASSERT_GT(n, 10);
  std::int64_t inside = 0;
  for (int layer : {n / 5, n / 2, 4 * n / 5}) {
    const LayerResult result = slicer.slice_layer(layer);
    EXPECT_EQ(result.stats.unresolved_pixels, 0) << name << " layer " << layer;
    inside += result.stats.pixels_inside;
  }
  EXPECT_GT(inside, 10000) << name;
}

TEST(SharedModels, TeapotReadsWithoutFoldsAndSlicesWithEveryPixelResolved) {
  if (test::shared_data_dir().empty()) GTEST_SKIP() << test::shared_data_missing_message();
  check_model("teapot", 4);
}

}  // namespace
}  // namespace trivox
