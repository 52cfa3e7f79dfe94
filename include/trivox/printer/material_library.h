// Named printer materials: the Stratasys J750/J850 model materials a scene may name instead
// of giving a colour ("materials": ["VeroCyan", ...]), each with a reference colour.
//
// The colours are display approximations chosen for previews and for telling materials apart
// in the Voxel Print images: they are not measured colours of printed parts, and GrabCAD maps
// image colours to the cartridges loaded, not to these values. Translucent materials carry an
// alpha below 255 so that previews show them as such.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace trivox {

struct LibraryMaterial {
  std::string_view name;             // as Stratasys writes it, e.g. "VeroCyan-V"
  std::string_view family;           // "Vero", "VeroVivid", "VeroClear", "Agilus30", "Tango"
  std::array<std::uint8_t, 4> rgba;  // sRGB + alpha, a display approximation
  // The material's code in GrabCAD Voxel Print packages (ConfigFile.xml's Material/Name, e.g.
  // "VeroCY-V"), where a public package writer or reader gives one (docs/FORMATS.md names
  // each source); empty otherwise.
  std::string_view code = {};
};

// Every library material, in a fixed order; names and colours are distinct.
std::span<const LibraryMaterial> material_library() noexcept;

// The library material called `name`, matched ignoring case, spaces, '-' and '_'
// ("Agilus30 Black", "agilus30-black" and "Agilus30Black" are one material), or else whose
// code matches the same way ("VeroCY-V" is VeroCyan-V); nullopt when there is none.
std::optional<LibraryMaterial> find_library_material(std::string_view name);

}  // namespace trivox
