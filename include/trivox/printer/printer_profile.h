// What the slicer needs to know about a printer: pixel pitch along both axes of a slice
// image, layer thickness, and how many materials one job may hold.
//
// Axes: x is the print head's fast axis (the width of a slice PNG), y the other in-plane
// axis (its height), z the build direction. Built-in profiles carry the values as published
// for the Stratasys J750/J850 Voxel Print workflow: 600 dpi along x, 300 dpi along y;
// layers of 0.014 mm in High Quality mode and 0.027 mm in High Mix and High Speed modes;
// 6 materials per job (3 in High Speed mode). "j750-paper" is the J750 with the 0.030 mm
// layers used in the reference paper this project reproduces.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace trivox {

struct PrinterProfile {
  std::string name;
  double x_dpi = 600.0;
  double y_dpi = 300.0;
  double layer_thickness_mm = 0.014;
  // Model materials one job may use (support material not counted).
  int max_materials = 6;

  // Centre-to-centre pixel distances, in millimetres.
  double pitch_x_mm() const noexcept { return 25.4 / x_dpi; }
  double pitch_y_mm() const noexcept { return 25.4 / y_dpi; }
  double pitch_z_mm() const noexcept { return layer_thickness_mm; }

  // Throws Error naming the profile and the field when x_dpi, y_dpi or layer_thickness_mm
  // is not finite and > 0, or max_materials < 1.
  void validate() const;

  bool operator==(const PrinterProfile&) const = default;
};

// The built-in profile called `name`, matched case-insensitively ("J750-HQ" works).
// Throws Error listing the known names when there is none.
PrinterProfile builtin_printer_profile(std::string_view name);

// The names of all built-in profiles, in a fixed order (lower case).
std::vector<std::string> builtin_printer_profile_names();

}  // namespace trivox
