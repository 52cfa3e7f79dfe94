#include "trivox/printer/material_library.h"

#include <cctype>
#include <string>

namespace trivox {

namespace {

// Colours: process-ink approximations for the CMY materials (the Vivid "-V" variants a
// little more saturated), near-black and near-white for the opaque neutrals, light tints
// with reduced alpha for the clear and translucent materials. VeroUltraWhite is pure white,
// the colour the public packages give it.
//
// Codes, from the public GCVF tools (docs/FORMATS.md): VeroCY-V, VeroMGT-V, VeroYL-V and
// VUltraWhite from slice2vox's buildGCVF.js; VeroCY-V, VeroMGT-V and UltraClear from
// voxelprint-preview's constants/materials.js.
constexpr LibraryMaterial kLibrary[] = {
    {"VeroCyan", "Vero", {0, 160, 227, 255}},
    {"VeroMagenta", "Vero", {236, 0, 140, 255}},
    {"VeroYellow", "Vero", {255, 237, 0, 255}},
    {"VeroCyan-V", "VeroVivid", {0, 147, 221, 255}, "VeroCY-V"},
    {"VeroMagenta-V", "VeroVivid", {221, 0, 132, 255}, "VeroMGT-V"},
    {"VeroYellow-V", "VeroVivid", {250, 225, 0, 255}, "VeroYL-V"},
    {"VeroUltraWhite", "Vero", {255, 255, 255, 255}, "VUltraWhite"},
    {"VeroBlack", "Vero", {30, 30, 30, 255}},
    {"VeroBlackPlus", "Vero", {20, 20, 20, 255}},
    {"VeroWhite", "Vero", {240, 240, 235, 255}},
    {"VeroWhitePlus", "Vero", {245, 245, 240, 255}},
    {"VeroPureWhite", "Vero", {252, 252, 252, 255}},
    {"VeroGray", "Vero", {128, 128, 128, 255}},
    {"VeroBlue", "Vero", {30, 80, 170, 255}},
    {"VeroClear", "VeroClear", {225, 240, 245, 96}},
    {"VeroUltraClear", "VeroClear", {235, 248, 252, 64}, "UltraClear"},
    {"Agilus30Black", "Agilus30", {40, 40, 40, 255}},
    {"Agilus30White", "Agilus30", {232, 232, 228, 255}},
    {"Agilus30Clear", "Agilus30", {220, 235, 230, 112}},
    {"TangoBlackPlus", "Tango", {50, 50, 50, 255}},
};

std::string folded(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == ' ' || c == '-' || c == '_') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

}  // namespace

std::span<const LibraryMaterial> material_library() noexcept { return kLibrary; }

std::optional<LibraryMaterial> find_library_material(std::string_view name) {
  const std::string key = folded(name);
  for (const LibraryMaterial& m : kLibrary)
    if (folded(m.name) == key) return m;
  for (const LibraryMaterial& m : kLibrary)
    if (!m.code.empty() && folded(m.code) == key) return m;
  return std::nullopt;
}

}  // namespace trivox
