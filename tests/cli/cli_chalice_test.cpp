// The bundled chalice (examples/scenes/chalice.json): its parts touch along flat faces instead
// of overlapping, and layers through the foot, the knotted stem and the cup slice without a
// failed or ambiguous inversion, every part showing its coloured curves.
#include <array>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "trivox/scene/scene.h"

namespace trivox::test {
namespace {

const std::filesystem::path kChalice = examples_dir() / "scenes" / "chalice.json";

TEST(Chalice, PartsAreStackedAndTouchAlongFlatFaces) {
  const Scene scene = read_scene(kChalice);
  ASSERT_EQ(scene.cells.size(), 5u);
  const Box3 foot = scene.cells[0].volume.bounds(), cup = scene.cells[4].volume.bounds();
  EXPECT_DOUBLE_EQ(foot.hi.z, 3.0);
  EXPECT_DOUBLE_EQ(cup.lo.z, 12.0);
  // The base's top is flat at z = 3 mm out to radius 4.5 mm (its parameters: u from the
  // bottom to the top, v outwards from the axis, flat for v <= 1/2, w around).
  for (double v : {0.0, 0.2, 0.5})
    for (double w : {0.0, 0.3, 0.8}) EXPECT_NEAR(scene.cells[0].volume.evaluate({1.0, v, w}).z, 3.0, 1e-12);
  const Vec3 rim = scene.cells[0].volume.evaluate({1.0, 0.5, 0.0});
  EXPECT_NEAR(std::hypot(rim.x, rim.y), 4.5, 1e-12);
  for (int s = 1; s <= 3; ++s) {
    const Volume& strand = scene.cells[static_cast<std::size_t>(s)].volume;
    // The strands' end discs lie in the planes of the base's top and the cup's bottom, within
    // the flat parts of both.
    for (double u : {0.0, 0.3, 1.0})
      for (double v : {0.0, 0.5, 1.0}) {
        const Vec3 bottom = strand.evaluate({u, v, 0}), top = strand.evaluate({u, v, 1});
        EXPECT_NEAR(bottom.z, 3.0, 1e-9);
        EXPECT_NEAR(top.z, 12.0, 1e-9);
        EXPECT_LT(std::hypot(bottom.x, bottom.y), 4.5);
        EXPECT_LT(std::hypot(top.x, top.y), 4.5);
      }
  }
  // The cup's bottom is flat at z = 12 mm out to radius 4.5 mm (its profile's outer side).
  for (double u : {0.0, 0.4})
    for (double w : {0.0, 0.1, 0.25}) EXPECT_NEAR(scene.cells[4].volume.evaluate({u, 0.0, w}).z, 12.0, 1e-12);
}

// Slices `layers` of the chalice and returns stats.json.
nlohmann::json slice(const std::string& layers) {
  ScratchDir dir;
  const CliResult r = run_cli("slice " + shell_quote(kChalice) + " -o " + shell_quote(dir.path()) + " --layers " + layers +
                              " --min-layers 1 -q -j 2");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(read_text(dir.path() / "stats.json"));
}

TEST(Chalice, SlicesThroughFootStemAndCupWithoutFailures) {
  // z = 1.5 mm (foot), 7.5 mm (three strands), 12.75 mm (the middle of the cup's bottom, which meets the axis), 20 mm
  // (the cup's wall, across the seam of the full turn).
  std::array<long, 4> colours{};
  for (const char* layers : {"51:51", "251:251", "426:426", "668:668"}) {
    SCOPED_TRACE(layers);
    const nlohmann::json stats = slice(layers);
    const nlohmann::json& t = stats.at("total");
    EXPECT_EQ(t.at("layers_sliced").get<int>(), 1);
    EXPECT_GT(t.at("pixels_inside").get<long>(), 500);
    EXPECT_EQ(t.at("unresolved_pixels").get<long>(), 0);
    EXPECT_EQ(t.at("folded_pixels").get<long>(), 0);
    // Clear material and coloured curves in every part; each colour somewhere.
    const auto per = t.at("voxels_per_material").get<std::vector<long>>();
    ASSERT_EQ(per.size(), 4u);
    EXPECT_GT(per[0], per[1] + per[2] + per[3]);  // mostly clear
    EXPECT_GT(per[1] + per[2] + per[3], 0);
    for (std::size_t m = 0; m < 4; ++m) colours[m] += per[m];
  }
  for (long n : colours) EXPECT_GT(n, 0);
}

}  // namespace
}  // namespace trivox::test
