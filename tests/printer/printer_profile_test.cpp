#include "trivox/printer/printer_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "trivox/error.h"

namespace trivox {
namespace {

TEST(PrinterProfileTest, BuiltinsCarryThePublishedValues) {
  struct Expected {
    const char* name;
    double layer_thickness_mm;
    int max_materials;
  };
  for (const Expected& e : {Expected{"j750-hq", 0.014, 6}, Expected{"j850-hq", 0.014, 6}, Expected{"j750-hm", 0.027, 6},
                            Expected{"j850-hm", 0.027, 6}, Expected{"j750-hs", 0.027, 3}, Expected{"j850-hs", 0.027, 3},
                            Expected{"j750-paper", 0.030, 6}}) {
    const PrinterProfile p = builtin_printer_profile(e.name);
    EXPECT_EQ(p.name, e.name);
    EXPECT_EQ(p.x_dpi, 600.0) << e.name;
    EXPECT_EQ(p.y_dpi, 300.0) << e.name;
    EXPECT_EQ(p.layer_thickness_mm, e.layer_thickness_mm) << e.name;
    EXPECT_EQ(p.max_materials, e.max_materials) << e.name;
  }
}

TEST(PrinterProfileTest, EveryListedNameResolvesAndValidates) {
  const std::vector<std::string> names = builtin_printer_profile_names();
  EXPECT_EQ(names.size(), 9u);
  for (const std::string& name : names) {
    const PrinterProfile p = builtin_printer_profile(name);
    EXPECT_EQ(p.name, name);
    EXPECT_NO_THROW(p.validate()) << name;
  }
}

TEST(PrinterProfileTest, LookupIgnoresCase) {
  EXPECT_EQ(builtin_printer_profile("J750-HQ"), builtin_printer_profile("j750-hq"));
  EXPECT_EQ(builtin_printer_profile("J850-Hm").name, "j850-hm");
}

TEST(PrinterProfileTest, UnknownNameListsTheKnownOnes) {
  try {
    builtin_printer_profile("j750-turbo");
    FAIL() << "no Error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("j750-turbo"), std::string::npos) << what;
    for (const std::string& name : builtin_printer_profile_names()) {
      EXPECT_NE(what.find(name), std::string::npos) << what;
    }
  }
  EXPECT_THROW(builtin_printer_profile(""), Error);
  EXPECT_THROW(builtin_printer_profile("j750-hq "), Error);
}

TEST(PrinterProfileTest, PitchesFollowTheResolution) {
  const PrinterProfile p = builtin_printer_profile("j750-hq");
  EXPECT_DOUBLE_EQ(p.pitch_x_mm(), 25.4 / 600.0);  // 0.0423 mm
  EXPECT_DOUBLE_EQ(p.pitch_y_mm(), 25.4 / 300.0);  // 0.0847 mm
  EXPECT_DOUBLE_EQ(p.pitch_z_mm(), 0.014);
}

TEST(PrinterProfileTest, ValidationNamesTheField) {
  auto message_for = [](const PrinterProfile& p) -> std::string {
    try {
      p.validate();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {0.0, -600.0, nan, inf}) {
    PrinterProfile p{"custom"};
    p.x_dpi = bad;
    EXPECT_NE(message_for(p).find("x_dpi"), std::string::npos) << bad;
    p = PrinterProfile{"custom"};
    p.y_dpi = bad;
    EXPECT_NE(message_for(p).find("y_dpi"), std::string::npos) << bad;
    p = PrinterProfile{"custom"};
    p.layer_thickness_mm = bad;
    EXPECT_NE(message_for(p).find("layer_thickness_mm"), std::string::npos) << bad;
  }
  PrinterProfile p{"custom"};
  p.max_materials = 0;
  EXPECT_NE(message_for(p).find("max_materials"), std::string::npos);
  EXPECT_NE(message_for(p).find("custom"), std::string::npos);
  EXPECT_EQ(message_for(PrinterProfile{"custom"}), "");  // the defaults are valid
}

// The resin printers: the displays of PrusaSlicer's profiles, square pixels of their pitch.
TEST(PrinterProfileTest, ResinPrintersCarryTheirDisplays) {
  struct Expected {
    const char* name;
    int px, py;
    double w, h, pitch;
  };
  for (const Expected& e :
       {Expected{"sl1", 2560, 1440, 120.96, 68.04, 0.04725}, Expected{"sl1s", 2560, 1620, 128.0, 81.0, 0.05}}) {
    const PrinterProfile p = builtin_printer_profile(e.name);
    ASSERT_TRUE(p.display.has_value()) << e.name;
    EXPECT_EQ(p.display->pixels_x, e.px);
    EXPECT_EQ(p.display->pixels_y, e.py);
    EXPECT_EQ(p.display->width_mm, e.w);
    EXPECT_EQ(p.display->height_mm, e.h);
    EXPECT_TRUE(p.display->portrait);
    EXPECT_TRUE(p.display->mirror_x);
    EXPECT_FALSE(p.display->mirror_y);
    EXPECT_NEAR(p.pitch_x_mm(), e.pitch, 1e-12) << e.name;
    EXPECT_NEAR(p.pitch_y_mm(), e.pitch, 1e-12) << e.name;
    EXPECT_EQ(p.layer_thickness_mm, 0.05);
    EXPECT_EQ(p.family, e.name);
    EXPECT_TRUE(printer_family_modes(p.family).empty());  // any layer height prints
    EXPECT_NO_THROW(p.validate());
  }
  EXPECT_EQ(builtin_printer_profile("sl1").display->printer_model, "SL1");
  EXPECT_EQ(builtin_printer_profile("sl1s").display->printer_model, "SL1S");
  for (const char* j : {"j750-hq", "j850-hm", "j750-paper"}) EXPECT_FALSE(builtin_printer_profile(j).display) << j;
}

TEST(PrinterProfileTest, DisplayWhosePitchIsNotTheProfilesIsRefused) {
  PrinterProfile p = builtin_printer_profile("sl1s");
  p.x_dpi = 600;
  try {
    p.validate();
    FAIL() << "no Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("display"), std::string::npos) << e.what();
  }
  p = builtin_printer_profile("sl1s");
  p.display->pixels_y = 0;
  EXPECT_THROW(p.validate(), Error);
}

TEST(PrinterProfileTest, TheJSeriesModes) {
  for (const char* family : {"j750", "j850", "J750"}) {
    const auto modes = printer_family_modes(family);
    ASSERT_EQ(modes.size(), 3u) << family;
    EXPECT_EQ(modes[0].name, "High Quality");
    EXPECT_EQ(modes[0].layer_thickness_mm, 0.014);
    EXPECT_EQ(modes[1].name, "High Mix");
    EXPECT_EQ(modes[1].layer_thickness_mm, 0.027);
    EXPECT_EQ(modes[2].name, "High Speed");
    EXPECT_EQ(modes[2].layer_thickness_mm, 0.027);
    EXPECT_EQ(modes[2].max_materials, 3);
  }
  EXPECT_TRUE(printer_family_modes("").empty());
  EXPECT_TRUE(printer_family_modes("objet").empty());
  // Every J-series profile but the paper's prints in a mode of its family.
  for (const std::string& name : builtin_printer_profile_names()) {
    const PrinterProfile p = builtin_printer_profile(name);
    EXPECT_EQ(layer_thickness_warning(p).has_value(), name == "j750-paper") << name;
  }
}

TEST(PrinterProfileTest, LayerThicknessOfNoModeIsWarnedWithTheHeightItPrints) {
  const auto paper = layer_thickness_warning(builtin_printer_profile("j750-paper"));
  ASSERT_TRUE(paper.has_value());
  for (const char* part : {"j750-paper", "0.03 mm", "J750", "High Quality 0.014 mm", "High Mix 0.027 mm",
                           "High Speed 0.027 mm", "10 % shorter"})
    EXPECT_NE(paper->find(part), std::string::npos) << part << " in " << *paper;
  // Nearest mode High Quality: 0.014 / 0.02 = 0.7.
  PrinterProfile p = builtin_printer_profile("j850-hq");
  p.name = "thicker";
  p.layer_thickness_mm = 0.02;
  const auto thicker = layer_thickness_warning(p);
  ASSERT_TRUE(thicker.has_value());
  EXPECT_NE(thicker->find("High Quality mode the part comes out 30 % shorter"), std::string::npos) << *thicker;
  EXPECT_NE(thicker->find("J850"), std::string::npos) << *thicker;
  // Thinner than every mode: the part comes out taller (0.014 / 0.01 = 1.4).
  p.layer_thickness_mm = 0.01;
  EXPECT_NE(layer_thickness_warning(p)->find("40 % taller"), std::string::npos) << *layer_thickness_warning(p);
  // Within half a micrometre of a mode: that mode.
  p.layer_thickness_mm = 0.0274;
  EXPECT_FALSE(layer_thickness_warning(p).has_value());
  p.layer_thickness_mm = 0.0276;
  EXPECT_TRUE(layer_thickness_warning(p).has_value());
  // No family, or a family that takes any layer: no warning.
  p.family.clear();
  EXPECT_FALSE(layer_thickness_warning(p).has_value());
  PrinterProfile resin = builtin_printer_profile("sl1s");
  resin.layer_thickness_mm = 0.0333;
  EXPECT_FALSE(layer_thickness_warning(resin).has_value());
}

}  // namespace
}  // namespace trivox
