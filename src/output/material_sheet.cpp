#include "trivox/output/detail/material_sheet.h"

#include <fmt/format.h>

#include "trivox/output/atomic_file.h"

namespace trivox {

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string row(int label, const std::string& name, const std::string& library, const std::array<std::uint8_t, 4>& c) {
  return fmt::format("{},{},{},#{:02X}{:02X}{:02X}{:02X},{},{},{},{}\n", label, csv_field(name), csv_field(library),
                     c[0], c[1], c[2], c[3], c[0], c[1], c[2], c[3]);
}

}  // namespace

std::string material_sheet_csv(const std::array<std::uint8_t, 4>& background_rgba,
                               const std::vector<MaterialSheetRow>& materials) {
  std::string text = "label,name,library,hex,r,g,b,a\n";
  text += row(0, "background", "", background_rgba);
  for (std::size_t j = 0; j < materials.size(); ++j) {
    const MaterialSheetRow& m = materials[j];
    text += row(static_cast<int>(j) + 1, m.name, m.library, m.rgba);
  }
  return text;
}

void write_material_sheet(const std::filesystem::path& path, const std::array<std::uint8_t, 4>& background_rgba,
                          const std::vector<MaterialSheetRow>& materials) {
  write_file_atomic(path, material_sheet_csv(background_rgba, materials));
}

}  // namespace trivox
