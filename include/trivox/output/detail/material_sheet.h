// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// The colour-to-material sheet written beside every job's images (materials.csv): which
// colour of the Voxel Print images stands for which material, so that the materials can be
// assigned in the printer software without opening the scene file.
//
// Format (RFC 4180 CSV, UTF-8, "\n" line ends, one header line):
//   label,name,library,hex,r,g,b,a
// one row for the background (label 0, name "background", the job's background colour) and
// one per scene material j (label j + 1, its name, the library material it matches or
// empty, its colour as #RRGGBBAA and as four 0..255 numbers). Fields holding a comma, a
// quote or a line break are quoted. The sheet depends only on the scene and the settings
// (voxel counts per material are in stats.json), so a resumed or sharded job writes the same
// bytes as one uninterrupted run.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace trivox {

struct MaterialSheetRow {
  std::string name;
  std::string library;  // empty for a custom material
  std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
};

// The sheet's text: the background row, then `materials` in label order.
std::string material_sheet_csv(const std::array<std::uint8_t, 4>& background_rgba,
                               const std::vector<MaterialSheetRow>& materials);

// Writes the sheet to `path` atomically (output/atomic_file.h). Throws IoError when it
// cannot be written.
void write_material_sheet(const std::filesystem::path& path, const std::array<std::uint8_t, 4>& background_rgba,
                          const std::vector<MaterialSheetRow>& materials);

}  // namespace trivox
