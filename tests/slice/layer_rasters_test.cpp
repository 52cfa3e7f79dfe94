// Slicer::slice_layer's copy of a layer before dithering (LayerRasters): dithering it again
// gives the layer's labels exactly, the mask is the inside set the statistics count, the
// fractions are 0 outside it, and asking for the copy changes nothing of the result.
#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "trivox/raster/dither.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

void expect_rasters_match(const Slicer& slicer, int layer) {
  const LayerResult plain = slicer.slice_layer(layer);
  const LayerResult r = slicer.slice_layer(layer, {.owner = true, .rasters = true});
  const std::vector<int>& owner = r.owner;
  const LayerRasters& rasters = r.rasters;
  EXPECT_EQ(r.labels, plain.labels) << "layer " << layer;
  const SliceLayout& L = slicer.layout();
  ASSERT_EQ(rasters.fractions.width_px(), L.width_px);
  ASSERT_EQ(rasters.fractions.height_px(), L.height_px);
  ASSERT_EQ(rasters.fractions.num_materials(), slicer.scene().num_materials());
  ASSERT_EQ(rasters.inside.width_px(), L.width_px);
  EXPECT_EQ(dither(rasters.fractions, rasters.inside, slicer.dither_params(), layer), r.labels) << "layer " << layer;
  std::int64_t inside = 0, with_material = 0;
  for (int y = 0; y < L.height_px; ++y)
    for (int x = 0; x < L.width_px; ++x) {
      const auto f = rasters.fractions.pixel(x, y);
      const bool any = std::any_of(f.begin(), f.end(), [](float v) { return v != 0.0f; });
      const std::size_t at =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(x);
      if (rasters.inside.inside(x, y)) {
        ++inside;
        with_material += any ? 1 : 0;
        EXPECT_GE(owner[at], 0);
      } else {
        EXPECT_FALSE(any) << "material outside the cells at (" << x << ", " << y << ")";
        EXPECT_EQ(owner[at], -1);
        EXPECT_EQ(r.labels.at(x, y), LabelImage::kVoid);
      }
    }
  EXPECT_EQ(inside, r.stats.pixels_inside);
  EXPECT_GT(with_material, 0) << "layer " << layer;
}

TEST(LayerRasters, ReditheringGivesTheLabelsOfAGradientCell) {
  std::vector<Cell> cells;
  cells.push_back(test::gradient_cell(test::box_volume({0, 0, 0}, {3, 2, 0.2})));
  const Scene scene = test::scene_with(std::move(cells), 2);
  const Slicer slicer(scene, {});
  for (int layer : {0, slicer.layout().num_layers / 2, slicer.layout().num_layers - 1})
    expect_rasters_match(slicer, layer);
}

TEST(LayerRasters, ReditheringGivesTheLabelsOfTheChalicesBooleanCells) {
  const Scene scene = read_scene(std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "scenes" / "chalice.json");
  const Slicer slicer(scene, {});
  // The knot in the base, in the stem and in the cup: several cells own pixels of each.
  for (int layer : {79, 249, 399}) expect_rasters_match(slicer, layer);
}

}  // namespace
}  // namespace trivox
