// The shell-trimmed box of examples/shared_scenes/duck_trimmed_box.json (the G+Smo duck B-rep of
// ../shared trimming a box) against an independent point-in-solid test: vertical rays through
// a tessellation of the duck twice as fine as the slicer's, unwelded. The slicer decides a
// shell by even-odd crossings along +x in each layer's plane; every pixel of the tested
// layers must agree except those within one pixel (or one layer) of the duck's surface or of
// the box's faces.
#include <array>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "support/test_support.h"
#include "trim/trim_fixtures.h"
#include "trivox/io/model.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {
namespace {

TEST(DuckTrimmedBox, AgreesWithVerticalRaysThroughAFinerTessellation) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Scene scene =
      read_scene(std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes" / "duck_trimmed_box.json");
  ASSERT_EQ(scene.cells.size(), 1u);
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();

  // The duck as the scene places it ("scale": 10 about the origin), read here on its own.
  const Model model = read_model(dir / "surfaces" / "duck_brep.xml");
  TrimShell duck;
  duck.name = "duck";
  for (const Patch& p : model.patches)
    if (p.spline.param_dim() == 2)
      duck.surfaces.push_back(p.spline.transformed([](std::span<double> q) {
        for (double& c : q) c *= 10;
      }));
  ASSERT_EQ(duck.surfaces.size(), 6u);
  const double pitch = std::min({L.pitch_x_mm, L.pitch_y_mm, L.layer_mm});
  const int production_samples = ShellMesh(duck, 0.125 * pitch).samples();
  const test::TriangleSoup soup(duck, 2 * production_samples);
  const test::VerticalRays rays(soup.triangles);

  // The crossings of every column's vertical line; a line through a hairline gap or an edge
  // of the soup moves by a hair (far below a pixel: the pixels that move could change are
  // within a hair of the surface, and never checked).
  const auto width = static_cast<std::size_t>(L.width_px);
  std::vector<std::vector<double>> columns(width * static_cast<std::size_t>(L.height_px));
  for (int row = 0; row < L.height_px; ++row)
    for (int col = 0; col < L.width_px; ++col) {
      auto& zs = columns[static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)];
      bool even = rays.crossings(L.x_of_col(col), L.y_of_row(row), zs);
      for (int k = 1; !even && k <= 8; ++k)
        even = rays.crossings(L.x_of_col(col) + k * 1.1e-7, L.y_of_row(row) + k * 0.7e-7, zs);
      ASSERT_TRUE(even) << "column " << col << ", " << row;
    }

  // Layers through the duck's body and the box's top (z = 3) and bottom (z = -7) halves.
  const double z_lo = -7, z_hi = 3;
  std::int64_t checked = 0, inside = 0, near = 0, mismatches = 0;
  for (double f : {0.1, 0.35, 0.6, 0.85}) {
    const int layer = static_cast<int>((z_lo + f * (z_hi - z_lo) - L.z0_mm) / L.layer_mm);
    ASSERT_GE(layer, 0);
    ASSERT_LT(layer, L.num_layers);
    const double z = L.z_of_layer(layer);
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    auto in_duck = [&](int col, int row) {
      if (col < 0 || row < 0 || col >= L.width_px || row >= L.height_px) return false;
      return test::VerticalRays::inside(columns[static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)],
                                        z);
    };
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const double x = L.x_of_col(col), y = L.y_of_row(row);
        const bool in = in_duck(col, row);
        // Near the duck: a crossing within a layer above or below, or a neighbour across.
        bool near_surface = in_duck(col - 1, row) != in || in_duck(col + 1, row) != in || in_duck(col, row - 1) != in ||
                            in_duck(col, row + 1) != in;
        for (double zc : columns[static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)])
          near_surface = near_surface || std::abs(zc - z) <= L.layer_mm;
        // The box [-8, 9] x [-13, 7] x [-7, 3], within one pixel of its faces.
        const double dx = L.pitch_x_mm, dy = L.pitch_y_mm;
        const bool in_box =
            x > -8 + dx && x < 9 - dx && y > -13 + dy && y < 7 - dy && z > -7 + L.layer_mm && z < 3 - L.layer_mm;
        const bool out_box = x < -8 - dx || x > 9 + dx || y < -13 - dy || y > 7 + dy;
        if (near_surface || !(in_box || out_box)) {
          ++near;
          continue;
        }
        const bool expected = in && in_box;
        const bool owned = owner[static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)] == 0;
        ++checked;
        inside += expected;
        if (owned != expected) {
          ++mismatches;
          ADD_FAILURE() << "layer " << layer << " pixel " << col << ", " << row << " (" << x << ", " << y << ", " << z
                        << "): sliced " << (owned ? "inside" : "outside") << ", vertical rays say "
                        << (expected ? "inside" : "outside");
        }
      }
  }
  std::cout << "duck-trimmed box: " << checked << " pixels checked (" << inside << " inside the duck and the box), "
            << near << " within one pixel of a surface not checked, " << mismatches << " disagree; tessellations of "
            << production_samples << " and " << 2 * production_samples << " samples per surface direction\n";
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(inside, 10000);
  EXPECT_GT(checked - inside, 10000);
}

}  // namespace
}  // namespace trivox
