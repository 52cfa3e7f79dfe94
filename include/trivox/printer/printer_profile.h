// What the slicer needs to know about a printer: pixel pitch along both axes of a slice
// image, layer thickness, and how many materials one job may hold; for a masked-resin printer
// also its display (size in pixels and millimetres, and how an image is laid on it).
//
// Axes: x is the print head's fast axis (the width of a slice PNG), y the other in-plane
// axis (its height), z the build direction. Built-in profiles (docs/SCENE.md, "Printer"):
//   - the Stratasys J750/J850 PolyJet printers at 600 x 300 dpi, one profile per print mode:
//     0.014 mm layers in High Quality, 0.027 mm in High Mix and High Speed; 6 materials per
//     job (3 in High Speed). "j750-paper" is the J750 with the 0.030 mm layers of the
//     reference paper, kept to reproduce its tables: no J750 mode prints that layer (see
//     layer_thickness_warning).
//   - the Prusa SL1 and SL1S masked-resin printers, display sizes as the printer profiles of
//     PrusaSlicer give them (SL1: 2560 x 1440 px over 120.96 x 68.04 mm; SL1S: 2560 x 1620 px
//     over 128 x 81 mm), square pixels, 0.05 mm layers by default (any layer height prints).
#pragma once

#include <algorithm>

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trivox {

// The LCD or DLP mask of a masked-resin printer, as PrusaSlicer's printer profiles describe it
// (display_pixels_x/y, display_width/height, display_orientation, display_mirror_x/y): x and
// y are the printer's bed axes. The archive writers place each layer image on it. With it,
// the settings an archive states for the printer (tilts, area_fill) and, until the scene's
// greyscale block says otherwise, the exposure of the printer's default resin profile.
struct MaskedDisplay {
  int pixels_x = 0, pixels_y = 0;      // along the bed's x and y
  double width_mm = 0, height_mm = 0;  // along x and y
  bool portrait = false;               // display_orientation = portrait (the image is turned: x runs down it)
  bool mirror_x = false, mirror_y = false;
  std::string printer_model;  // config.ini's printerModel, e.g. "SL1S"
  // A layer exposing at most this share of the display (percent) tilts fast, others slowly.
  double area_fill_percent = 50;
  double fast_tilt_s = 5, slow_tilt_s = 8;
  // Exposure (seconds) of a layer, of the first layers, and the layers over which the first
  // exposure fades into the other.
  double exposure_s = 7.5, initial_exposure_s = 35;
  int faded_layers = 10;
  // The exposures (seconds) the printer takes, for a layer and for the first layers: the limits
  // Prusa's SL1 and SL1S firmware sets (1 to 60 s, and 10 to 120 s). A scene's greyscale block
  // that asks for more or less is refused; the archive would state it to the printer.
  double min_exposure_s = 1, max_exposure_s = 60;
  double min_initial_exposure_s = 10, max_initial_exposure_s = 120;
  // The resin the exposures are for, as the archive's config.ini names it (materialName): the
  // default resin profile's name, or the scene's greyscale "resin"; empty when not known (a
  // printer of one's own, or exposures a scene set without naming its resin).
  std::string resin{};

  bool operator==(const MaskedDisplay&) const = default;
};

struct PrinterProfile {
  std::string name;
  double x_dpi = 600.0;
  double y_dpi = 300.0;
  double layer_thickness_mm = 0.014;
  // Model materials one job may use (support material not counted). On a masked-resin printer
  // the materials of a scene are exposure levels of its one resin (the scene's "greyscale").
  int max_materials = 6;
  // The printer family the profile belongs to: "j750", "j850", "sl1", "sl1s"; empty for a
  // custom printer. The family's print modes (printer_family_modes) decide the layer warning.
  std::string family{};
  // The print mode of a built-in J750/J850 profile and of a profile based on one ("High
  // Speed"; printer_family_modes); empty otherwise.
  std::string print_mode{};
  // The display of a masked-resin printer; none for the others.
  std::optional<MaskedDisplay> display{};

  // Centre-to-centre pixel distances, in millimetres.
  double pitch_x_mm() const noexcept { return 25.4 / x_dpi; }
  double pitch_y_mm() const noexcept { return 25.4 / y_dpi; }
  double pitch_z_mm() const noexcept { return layer_thickness_mm; }
  // The finest of the three pitches: the scale below which the slicer's decisions and the
  // scene's checks (a mesh's intersections, a volume's resolution) count nothing.
  double finest_pitch_mm() const noexcept { return std::min({pitch_x_mm(), pitch_y_mm(), pitch_z_mm()}); }

  // Throws Error naming the profile and the field when x_dpi, y_dpi or layer_thickness_mm
  // is not finite and > 0, max_materials < 1, or a display is given whose sizes are not
  // positive or whose pitch differs from the profile's (by more than a part in a million).
  void validate() const;

  bool operator==(const PrinterProfile&) const = default;
};

// One print mode of a printer family: the layer it prints and the materials one job may use.
struct PrintMode {
  std::string_view name;  // as the printer's software names it, e.g. "High Mix"
  double layer_thickness_mm;
  int max_materials;
};

// The print modes of a family ("j750", "j850"), in a fixed order; empty for a family whose
// printers take any layer height (the resin printers) and for an unknown family.
std::span<const PrintMode> printer_family_modes(std::string_view family) noexcept;

// GrabCAD Voxel Print prints at most this many model material colours in one job.
inline constexpr int kVoxelPrintMaxMaterials = 6;
// The most materials a Voxel Print stack or package (formats "voxelprint", "gcvf") may hold
// on this profile, whatever its max_materials says: 6, or the fewer its print mode takes (3
// in High Speed).
int voxel_print_max_materials(const PrinterProfile& profile) noexcept;

// A warning for a profile whose family has print modes none of which prints its layer
// thickness (within half a micrometre): the printer would lay a stack of such layers at the
// thickness of the mode it runs in, so the part comes out shorter or taller than modelled. It
// names the modes and how much the height changes in the nearest one. nullopt otherwise.
std::optional<std::string> layer_thickness_warning(const PrinterProfile& profile);

// The built-in profile called `name`, matched case-insensitively ("J750-HQ" works).
// Throws Error listing the known names when there is none.
PrinterProfile builtin_printer_profile(std::string_view name);

// The names of all built-in profiles, in a fixed order (lower case).
std::vector<std::string> builtin_printer_profile_names();

}  // namespace trivox
