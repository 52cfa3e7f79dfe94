// Display colours: the colour difference, the nearly equal pairs of a material list, and the
// preview colours that keep every material apart.
#include "trivox/output/display_colours.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "trivox/printer/material_library.h"

namespace trivox {
namespace {

Rgba library(std::string_view name) { return find_library_material(name).value().rgba; }
Rgb rgb(const Rgba& c) { return {c[0], c[1], c[2]}; }

TEST(DisplayColours, ColourDifferenceIsCielabDistance) {
  EXPECT_NEAR(colour_difference({0, 0, 0}, {255, 255, 255}), 100.0, 1e-3);  // L* from 0 to 100
  EXPECT_EQ(colour_difference({12, 200, 99}, {12, 200, 99}), 0.0);
  EXPECT_NEAR(colour_difference({255, 0, 0}, {0, 0, 255}), colour_difference({0, 0, 255}, {255, 0, 0}), 1e-12);
  // The pair the first-hour user met: a person cannot tell them apart.
  const double whites = colour_difference(rgb(library("VeroWhite")), rgb(library("Agilus30White")));
  EXPECT_GT(whites, 1.0);
  EXPECT_LT(whites, 5.0);
  EXPECT_GT(colour_difference(rgb(library("VeroCyan")), rgb(library("VeroMagenta"))), 50.0);
}

TEST(DisplayColours, NearlyEqualPairsAreFound) {
  const std::vector<Rgba> materials = {library("VeroCyan"), library("VeroWhite"), library("VeroMagenta"),
                                       library("Agilus30White")};
  const std::vector<SimilarColours> pairs = similar_colours(materials);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].first, 1);
  EXPECT_EQ(pairs[0].second, 3);
  EXPECT_LT(pairs[0].difference, kDistinctColourDifference);
  EXPECT_TRUE(similar_colours({library("VeroCyan"), library("VeroMagenta"), library("VeroYellow")}).empty());
}

// Distinct colours show as they are; nearly equal ones are moved apart from each other and
// from the background, deterministically.
TEST(DisplayColours, PreviewsKeepEveryMaterialApart) {
  const Rgba white{255, 255, 255, 255};
  const std::vector<Rgba> distinct = {library("VeroCyan"), library("VeroMagenta"), library("VeroYellow")};
  const std::vector<Rgb> same = display_colours(distinct, white);
  for (std::size_t j = 0; j < distinct.size(); ++j) EXPECT_EQ(same[j], rgb(distinct[j]));

  std::vector<Rgba> all;
  for (const LibraryMaterial& m : material_library()) all.push_back(m.rgba);
  // Adversarial: eight materials of one colour, and the whole library.
  for (const std::vector<Rgba>& materials : {std::vector<Rgba>(8, Rgba{240, 240, 235, 255}), all}) {
    const std::vector<Rgb> shown = display_colours(materials, white);
    ASSERT_EQ(shown.size(), materials.size());
    EXPECT_EQ(shown, display_colours(materials, white));
    for (std::size_t i = 0; i < shown.size(); ++i) {
      if (shown[i] != rgb(materials[i])) {  // moved: clear of the background too
        EXPECT_GE(colour_difference(shown[i], rgb(white)), kDisplayColourSeparation) << i;
      }
      for (std::size_t j = i + 1; j < shown.size(); ++j)
        EXPECT_GE(colour_difference(shown[i], shown[j]), kDistinctColourDifference) << i << " " << j;
    }
  }
}

// The previews' background stands apart from every material: black for light materials (as
// before), white for dark ones (the README's own VeroWhite + Agilus30Black pair cannot use
// either: a mid grey), and where no candidate stands apart, the one farthest from its
// nearest material; a material nearly the background is then shown in another colour.
TEST(DisplayColours, ThePreviewBackgroundStandsApartFromEveryMaterial) {
  const Rgba black{0, 0, 0, 255}, white{255, 255, 255, 255};
  EXPECT_EQ(preview_background({library("VeroCyan"), library("VeroMagenta"), library("VeroWhite")}), black);
  EXPECT_EQ(preview_background({library("Agilus30Black")}), white);
  EXPECT_EQ(preview_background({library("VeroBlack"), library("VeroCyan")}), white);
  const Rgba pair = preview_background({library("VeroWhite"), library("Agilus30Black")});
  EXPECT_NE(pair, black);
  EXPECT_NE(pair, white);
  for (const char* m : {"VeroWhite", "Agilus30Black"})
    EXPECT_GE(colour_difference(rgb(pair), rgb(library(m))), kDisplayColourSeparation) << m;
  EXPECT_EQ(preview_background({}), black);
  // Every candidate taken: the farthest from its nearest material, and never a failure.
  const std::vector<Rgba> greys = {black, white, {64, 64, 64, 255}, {128, 128, 128, 255}, {192, 192, 192, 255}};
  const Rgba chosen = preview_background(greys);
  EXPECT_NE(std::find(greys.begin(), greys.end(), chosen), greys.end());
  // A material equal to the background is moved off it.
  const std::vector<Rgb> shown = display_colours({library("Agilus30Black")}, library("Agilus30Black"));
  EXPECT_GE(colour_difference(shown[0], rgb(library("Agilus30Black"))), kDisplayColourSeparation);
}

}  // namespace
}  // namespace trivox
