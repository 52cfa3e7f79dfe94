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
  EXPECT_EQ(names.size(), 7u);
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

}  // namespace
}  // namespace trivox
