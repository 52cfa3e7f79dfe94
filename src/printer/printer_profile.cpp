#include "trivox/printer/printer_profile.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>

#include "trivox/error.h"

namespace trivox {

namespace {

struct BuiltinProfile {
  std::string_view name;
  double layer_thickness_mm;
  int max_materials;
};

// Values as published for the J750/J850 Voxel Print workflow (see the header); every
// built-in profile prints at 600 x 300 dpi.
constexpr std::array<BuiltinProfile, 7> kBuiltins{{
    {"j750-hq", 0.014, 6},
    {"j850-hq", 0.014, 6},
    {"j750-hm", 0.027, 6},
    {"j850-hm", 0.027, 6},
    {"j750-hs", 0.027, 3},
    {"j850-hs", 0.027, 3},
    {"j750-paper", 0.030, 6},
}};

char ascii_lower(char c) noexcept { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool equal_ignoring_case(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (ascii_lower(a[i]) != ascii_lower(b[i])) return false;
  }
  return true;
}

void require_positive(const PrinterProfile& profile, const char* field, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw Error(fmt::format("printer profile '{}': {} = {} is not a finite value > 0", profile.name, field, value));
  }
}

}  // namespace

void PrinterProfile::validate() const {
  require_positive(*this, "x_dpi", x_dpi);
  require_positive(*this, "y_dpi", y_dpi);
  require_positive(*this, "layer_thickness_mm", layer_thickness_mm);
  if (max_materials < 1) {
    throw Error(fmt::format("printer profile '{}': max_materials = {} is not >= 1", name, max_materials));
  }
}

PrinterProfile builtin_printer_profile(std::string_view name) {
  for (const BuiltinProfile& builtin : kBuiltins) {
    if (equal_ignoring_case(builtin.name, name)) {
      PrinterProfile profile;
      profile.name = std::string(builtin.name);
      profile.x_dpi = 600.0;
      profile.y_dpi = 300.0;
      profile.layer_thickness_mm = builtin.layer_thickness_mm;
      profile.max_materials = builtin.max_materials;
      return profile;
    }
  }
  throw Error(fmt::format("unknown printer profile '{}'; known profiles: {}", name,
                          fmt::join(builtin_printer_profile_names(), ", ")));
}

std::vector<std::string> builtin_printer_profile_names() {
  std::vector<std::string> names;
  names.reserve(kBuiltins.size());
  for (const BuiltinProfile& builtin : kBuiltins) names.emplace_back(builtin.name);
  return names;
}

}  // namespace trivox
