#include "trivox/printer/material_library.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace trivox {
namespace {

TEST(MaterialLibrary, NamesAndColoursAreDistinct) {
  std::set<std::string> names;
  std::set<std::array<std::uint8_t, 4>> colours;
  for (const LibraryMaterial& m : material_library()) {
    EXPECT_TRUE(names.insert(std::string(m.name)).second) << m.name;
    EXPECT_TRUE(colours.insert(m.rgba).second) << m.name;
    EXPECT_FALSE(m.family.empty()) << m.name;
    // Every entry is found by its own name, and no two names fold to the same key.
    const auto found = find_library_material(m.name);
    ASSERT_TRUE(found.has_value()) << m.name;
    EXPECT_EQ(found->name, m.name);
  }
  for (const char* required : {"VeroCyan", "VeroMagenta", "VeroYellow", "VeroBlack", "VeroWhite", "VeroPureWhite",
                               "VeroClear", "VeroUltraClear", "Agilus30Black", "Agilus30White", "Agilus30Clear"})
    EXPECT_TRUE(names.count(required)) << required;
}

TEST(MaterialLibrary, LookupIgnoresCaseSpacesAndSeparators) {
  EXPECT_EQ(find_library_material("verocyan")->name, "VeroCyan");
  EXPECT_EQ(find_library_material("Agilus30 Black")->name, "Agilus30Black");
  EXPECT_EQ(find_library_material("agilus30_clear")->name, "Agilus30Clear");
  EXPECT_EQ(find_library_material("VeroCyan-V")->name, "VeroCyan-V");
  EXPECT_EQ(find_library_material("VEROCYANV")->name, "VeroCyan-V");
  EXPECT_FALSE(find_library_material("Vero").has_value());
  EXPECT_FALSE(find_library_material("").has_value());
  // Clear materials preview as translucent, the opaque ones as opaque.
  EXPECT_LT(find_library_material("VeroClear")->rgba[3], 255);
  EXPECT_EQ(find_library_material("VeroBlack")->rgba[3], 255);
}

}  // namespace
}  // namespace trivox
