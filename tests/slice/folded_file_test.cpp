// A folded model FILE (G+Smo's tensorBSpline.xml: 26 of its 343 Jacobian samples positive,
// the rest negative) in a scene: refused without "allow_fold", sliced with it by the fold
// rules (docs/SCENE.md, "Folded cells"). The layer's counts agree with an independent count
// over every pixel of the bitmap by the global solver: inside where a pixel has a preimage,
// folded where it has two or more regular ones; and each pixel's parameters are those of its
// preimage of largest |det J|.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "slice/cell_tracer.h"
#include "slice/fold_candidates.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// The 0.1 x 0.22 x 0.3 model scaled by 40 (4 x 9 x 12 mm), at 150 dpi and 0.5 mm layers: a
// few thousand pixels a layer, each decided by the global solver.
std::string scene_text(const fs::path& model, bool allow_fold) {
  return fmt::format(R"({{
  "version": 1, "units": "mm",
  "printer": {{ "base": "j750-hq", "x_dpi": 150, "y_dpi": 150, "layer_thickness_mm": 0.5 }},
  "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [{{
    "name": "folded",
    "geometry": {{ "file": {}, "patch": 0{} }},
    "placement": {{ "scale": 40 }},
    "material": {{ "kind": "expression", "fractions": {{ "VeroCyan": "w", "VeroMagenta": "1 - w" }} }}
  }}]
}})",
                     nlohmann::json(model.string()).dump(), allow_fold ? ", \"allow_fold\": true" : "");
}

class FoldedFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path data = test::shared_data_dir();
    if (data.empty()) GTEST_SKIP() << test::shared_data_missing_message();
    model_ = data / "volumes/gismo/tensorBSpline.xml";
  }
  fs::path model_;
};

TEST_F(FoldedFile, IsRefusedWithoutTheOption) {
  try {
    parse_scene(scene_text(model_, false), fs::temp_directory_path() / "scene.json");
    FAIL() << "a folded file model was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/cells/0/geometry"), std::string::npos) << what;
    EXPECT_NE(what.find("folds over itself"), std::string::npos) << what;
    EXPECT_NE(what.find("u [0.167, 0.833] v [0, 1] w [0.667, 1]"), std::string::npos) << what;  // where
    EXPECT_NE(what.find("\"allow_fold\": true"), std::string::npos) << what;
  }
}

TEST_F(FoldedFile, SlicesWithTheOptionAndCountsAgreeWithTheGlobalSolverOnEveryPixel) {
  const Scene scene = parse_scene(scene_text(model_, true), fs::temp_directory_path() / "scene.json");
  ASSERT_EQ(scene.cells.size(), 1u);
  const Cell& cell = scene.cells[0];
  EXPECT_TRUE(cell.folds);
  const Slicer slicer(scene, SliceParams{});
  const SliceLayout& L = slicer.layout();
  const GlobalSolver solver(cell.volume);
  const GlobalSolveParams global = slicer.params().global;

  std::int64_t total_folded = 0;
  int layers_with_folds = 0;
  for (int layer = 0; layer < L.num_layers; layer += 3) {
    SCOPED_TRACE(fmt::format("layer {}", layer));
    const LayerResult r = slicer.slice_layer(layer);
    const double z = L.z_of_layer(layer);
    // The independent count: every pixel of the bitmap, not only the slicer's candidates.
    std::int64_t inside = 0, folded = 0;
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const GlobalResult g = solver.solve({L.x_of_col(col), L.y_of_row(row), z}, global);
        ASSERT_NE(g.status, GlobalStatus::kIncomplete);
        inside += !g.preimages.empty();
        folded += g.status == GlobalStatus::kMultiple;
        EXPECT_EQ(r.labels.at(col, row) != 0, !g.preimages.empty()) << col << ' ' << row;
      }
    EXPECT_EQ(r.stats.pixels_inside, inside);
    EXPECT_EQ(r.stats.folded_pixels, folded);
    total_folded += folded;
    layers_with_folds += folded > 0;
  }
  // The fold is real at this resolution: many pixels on several layers have two preimages.
  EXPECT_GE(layers_with_folds, 2);
  EXPECT_GE(total_folded, 50);
}

// The tracer of a folded cell gives each pixel the parameters of its preimage of largest
// |det J| (the lexicographically first of equal ones), as found independently here.
TEST_F(FoldedFile, EachPixelTakesThePreimageOfLargestJacobian) {
  const Scene scene = parse_scene(scene_text(model_, true), fs::temp_directory_path() / "scene.json");
  const Cell& cell = scene.cells[0];
  const Slicer slicer(scene, SliceParams{});
  const SliceLayout& L = slicer.layout();
  const GlobalSolver solver(cell.volume);
  const detail::FoldCandidates candidates(cell.volume);
  int checked_folds = 0;
  for (int layer = 0; layer < L.num_layers; layer += 4) {
    const double z = L.z_of_layer(layer);
    detail::RowSpans spans;
    candidates.spans(L, z, 0.0, spans);
    detail::CellTracer tracer(cell.volume, solver, slicer.params(), L.width_px,
                              detail::CellTracer::kDefaultRowsInFlight, true);
    tracer.trace_layer(L, z, spans, [&](int row, const detail::TracedRow& traced) {
      for (std::size_t k = 0; k < traced.cols.size(); ++k) {
        const GlobalResult g = solver.solve({L.x_of_col(traced.cols[k]), L.y_of_row(row), z}, slicer.params().global);
        ASSERT_FALSE(g.preimages.empty());
        std::size_t best = 0;
        for (std::size_t i = 1; i < g.preimages.size(); ++i)
          if (std::abs(g.preimages[i].det) > std::abs(g.preimages[best].det)) best = i;
        EXPECT_EQ(traced.uvw[k], g.preimages[best].uvw) << traced.cols[k] << ' ' << row;
        if (g.status == GlobalStatus::kMultiple && best != 0) ++checked_folds;
      }
    });
  }
  // Folded pixels whose largest |det J| is not the first preimage in (u, v, w) order: the
  // rule differs from "the first one" there.
  EXPECT_GT(checked_folds, 0);
}

TEST(ChoosePreimage, LargestAbsoluteDeterminantThenTheFirstInParameterOrder) {
  const std::vector<Preimage> p = {{{0.1, 0.5, 0.5}, 0, -2.0}, {{0.2, 0.1, 0.1}, 0, 3.0}, {{0.3, 0.0, 0.0}, 0, -3.0}};
  EXPECT_EQ(detail::choose_preimage(p).uvw, (Vec3{0.2, 0.1, 0.1}));
  const std::vector<Preimage> q = {{{0.1, 0.5, 0.5}, 0, 1e-12}, {{0.7, 0.1, 0.1}, 0, -0.5}};
  EXPECT_EQ(detail::choose_preimage(q).uvw, (Vec3{0.7, 0.1, 0.1}));
}

}  // namespace
}  // namespace trivox
