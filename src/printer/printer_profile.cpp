#include "trivox/printer/printer_profile.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "trivox/error.h"
#include "trivox/limits.h"

namespace trivox {

namespace {

// The J750 and J850 print modes (docs/SCENE.md, "Printer", gives the sources): the layer is
// what GrabCAD Voxel Print expects of a stack sliced for the mode.
constexpr std::array<PrintMode, 3> kPolyJetModes{{
    {"High Quality", 0.014, 6},
    {"High Mix", 0.027, 6},
    {"High Speed", 0.027, 3},
}};

// The displays as PrusaSlicer 2.5's printer profiles "Original Prusa SL1" and "Original Prusa
// SL1S SPEED" give them (display_pixels_x/y, display_width/height, display_orientation,
// display_mirror_x/y; display_mirror_x is PrusaSlicer's default 1 for the SL1), with their
// area_fill and tilt times (the SL1's are PrusaSlicer's defaults: 50 %, 5 s, 8 s) and the
// exposure of each printer's default material, "Prusa Orange Tough @0.05" (7.5 s, 35 s first)
// and "... @0.05 SL1S" (2 s, 25 s first), 10 faded layers.
MaskedDisplay sl1_display() {
  MaskedDisplay d{2560, 1440, 120.96, 68.04, true, true, false, "SL1", 50, 5, 8, 7.5, 35, 10};
  d.resin = "Prusa Orange Tough @0.05";
  return d;
}
MaskedDisplay sl1s_display() {
  MaskedDisplay d{2560, 1620, 128.0, 81.0, true, true, false, "SL1S", 45, 2.5, 5, 2, 25, 10};
  d.resin = "Prusa Orange Tough @0.05 SL1S";
  return d;
}

struct BuiltinProfile {
  std::string_view name;
  std::string_view family;
  double layer_thickness_mm;
  int max_materials;
  MaskedDisplay (*display)();  // null for a printer without a mask
  std::string_view mode = {};  // the print mode (kPolyJetModes) of a J750/J850 profile
};

constexpr std::array<BuiltinProfile, 9> kBuiltins{{
    {"j750-hq", "j750", 0.014, 6, nullptr, "High Quality"},
    {"j850-hq", "j850", 0.014, 6, nullptr, "High Quality"},
    {"j750-hm", "j750", 0.027, 6, nullptr, "High Mix"},
    {"j850-hm", "j850", 0.027, 6, nullptr, "High Mix"},
    {"j750-hs", "j750", 0.027, 3, nullptr, "High Speed"},
    {"j850-hs", "j850", 0.027, 3, nullptr, "High Speed"},
    {"j750-paper", "j750", 0.030, 6, nullptr},
    {"sl1", "sl1", 0.05, kMaxMaterials, sl1_display},
    {"sl1s", "sl1s", 0.05, kMaxMaterials, sl1s_display},
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

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

}  // namespace

void PrinterProfile::validate() const {
  require_positive(*this, "x_dpi", x_dpi);
  require_positive(*this, "y_dpi", y_dpi);
  require_positive(*this, "layer_thickness_mm", layer_thickness_mm);
  if (max_materials < 1) {
    throw Error(fmt::format("printer profile '{}': max_materials = {} is not >= 1", name, max_materials));
  }
  if (display) {
    if (display->pixels_x < 1 || display->pixels_y < 1)
      throw Error(fmt::format("printer profile '{}': the display of {} x {} px has no pixels", name, display->pixels_x,
                              display->pixels_y));
    require_positive(*this, "display width_mm", display->width_mm);
    require_positive(*this, "display height_mm", display->height_mm);
    // The layer images are laid pixel for pixel on the display: its pitch is the profile's.
    const double px = display->width_mm / display->pixels_x, py = display->height_mm / display->pixels_y;
    if (std::abs(px - pitch_x_mm()) > 1e-6 * px || std::abs(py - pitch_y_mm()) > 1e-6 * py)
      throw Error(
          fmt::format("printer profile '{}': the display's pixels are {} x {} mm but the profile's pitch is {} x {} mm",
                      name, px, py, pitch_x_mm(), pitch_y_mm()));
  }
}

std::span<const PrintMode> printer_family_modes(std::string_view family) noexcept {
  if (equal_ignoring_case(family, "j750") || equal_ignoring_case(family, "j850")) return kPolyJetModes;
  return {};
}

int voxel_print_max_materials(const PrinterProfile& profile) noexcept {
  for (const PrintMode& m : printer_family_modes(profile.family))
    if (m.name == profile.print_mode) return std::min(kVoxelPrintMaxMaterials, m.max_materials);
  return kVoxelPrintMaxMaterials;
}

std::optional<std::string> layer_thickness_warning(const PrinterProfile& profile) {
  const std::span<const PrintMode> modes = printer_family_modes(profile.family);
  if (modes.empty() || !(profile.layer_thickness_mm > 0)) return std::nullopt;
  const PrintMode* nearest = &modes.front();
  std::vector<std::string> listed;
  for (const PrintMode& m : modes) {
    if (std::abs(m.layer_thickness_mm - profile.layer_thickness_mm) <= 0.5e-3) return std::nullopt;
    if (std::abs(m.layer_thickness_mm - profile.layer_thickness_mm) <
        std::abs(nearest->layer_thickness_mm - profile.layer_thickness_mm))
      nearest = &m;
    listed.push_back(fmt::format("{} {} mm", m.name, m.layer_thickness_mm));
  }
  // The printer lays every image at its mode's layer: the stack's height scales by the ratio.
  const double change = 100.0 * (nearest->layer_thickness_mm / profile.layer_thickness_mm - 1.0);
  return fmt::format(
      "printer '{}': the layer thickness {} mm is no print mode of the {} ({}); printed in {} mode the part "
      "comes out {:.3g} % {} than modelled",
      profile.name, profile.layer_thickness_mm, upper(profile.family), fmt::join(listed, ", "), nearest->name,
      std::abs(change), change < 0 ? "shorter" : "taller");
}

PrinterProfile builtin_printer_profile(std::string_view name) {
  for (const BuiltinProfile& builtin : kBuiltins) {
    if (equal_ignoring_case(builtin.name, name)) {
      PrinterProfile profile;
      profile.name = std::string(builtin.name);
      profile.family = std::string(builtin.family);
      profile.layer_thickness_mm = builtin.layer_thickness_mm;
      profile.max_materials = builtin.max_materials;
      profile.print_mode = std::string(builtin.mode);
      if (builtin.display != nullptr) {
        profile.display = builtin.display();
        // Square pixels of the display's pitch.
        profile.x_dpi = 25.4 * profile.display->pixels_x / profile.display->width_mm;
        profile.y_dpi = 25.4 * profile.display->pixels_y / profile.display->height_mm;
      } else {
        profile.x_dpi = 600.0;
        profile.y_dpi = 300.0;
      }
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
