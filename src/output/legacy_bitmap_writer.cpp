// The "legacy" output: the bitmap method of the paper's printer (an Objet Connex fed one
// bitmap per material per slice): one 1-bit BMP per material per layer and a text file
// naming the layer thickness, the slice count and every bitmap (docs/FORMATS.md).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "output/material_bits.h"
#include "output/stack_writers.h"
#include "trivox/error.h"
#include "trivox/output/atomic_file.h"

namespace trivox::detail {

namespace {

void put_u16(std::string& out, std::uint32_t v) {
  out += static_cast<char>(v & 0xff);
  out += static_cast<char>((v >> 8) & 0xff);
}
void put_u32(std::string& out, std::uint32_t v) {
  put_u16(out, v & 0xffff);
  put_u16(out, v >> 16);
}

// Pixels per metre for a pitch in mm (BMP's resolution field).
std::uint32_t pixels_per_metre(double pitch_mm) { return static_cast<std::uint32_t>(std::lround(1000.0 / pitch_mm)); }

}  // namespace

std::string encode_bmp1(int width_px, int height_px, const std::uint8_t* bits, double pitch_x_mm, double pitch_y_mm) {
  const std::uint32_t stride = ((static_cast<std::uint32_t>(width_px) + 31u) / 32u) * 4u;  // rows padded to 4 bytes
  const std::uint32_t image_bytes = stride * static_cast<std::uint32_t>(height_px);
  const std::uint32_t offset = 14 + 40 + 2 * 4;
  std::string out;
  out.reserve(offset + image_bytes);
  // BITMAPFILEHEADER
  out += "BM";
  put_u32(out, offset + image_bytes);
  put_u32(out, 0);
  put_u32(out, offset);
  // BITMAPINFOHEADER: positive height = rows stored bottom-up.
  put_u32(out, 40);
  put_u32(out, static_cast<std::uint32_t>(width_px));
  put_u32(out, static_cast<std::uint32_t>(height_px));
  put_u16(out, 1);  // planes
  put_u16(out, 1);  // bits per pixel
  put_u32(out, 0);  // BI_RGB, uncompressed
  put_u32(out, image_bytes);
  put_u32(out, pixels_per_metre(pitch_x_mm));
  put_u32(out, pixels_per_metre(pitch_y_mm));
  put_u32(out, 2);  // colours used
  put_u32(out, 2);  // colours important
  // Palette (B, G, R, 0): index 0 black = no material, index 1 white = material.
  put_u32(out, 0x00000000u);
  put_u32(out, 0x00ffffffu);
  std::string row(stride, '\0');
  for (int y = height_px - 1; y >= 0; --y) {
    std::fill(row.begin(), row.end(), '\0');
    const std::uint8_t* in = bits + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_px);
    for (int x = 0; x < width_px; ++x)
      if (in[x] != 0)
        row[static_cast<std::size_t>(x / 8)] =
            static_cast<char>(row[static_cast<std::size_t>(x / 8)] | (0x80 >> (x % 8)));
    out += row;
  }
  return out;
}

namespace {

class LegacyBitmapWriter final : public LayerWriter {
 public:
  explicit LegacyBitmapWriter(OutputContext c) : c_(std::move(c)) {
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "legacy", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "legacy").string(), ec.message()));
  }
  std::string_view name() const noexcept override { return "legacy"; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    std::vector<std::string> files;
    detail::for_each_material_bits(
        labels, c_.material_names.size(), [&](std::size_t j, const std::vector<std::uint8_t>& bits) {
          const std::string file = file_name(index, j);
          write_file_atomic(c_.dir / file, encode_bmp1(labels.width_px(), labels.height_px(), bits.data(),
                                                       c_.pitch_x_mm, c_.pitch_y_mm));
          files.push_back(file);
        });
    return files;
  }

  StackCost stack_cost(const StackSampling&) const override { return {1, slices_text().size(), 0, 0}; }

  // The text manifest: known from the settings alone, written when the job completes.
  std::vector<std::string> finish() const override {
    const std::string file = "legacy/slices.txt";
    write_file_atomic(c_.dir / file, slices_text());
    return {file};
  }

 private:
  std::string slices_text() const {
    std::string text = "# trivox legacy bitmap job: one 1-bit BMP per material per slice (1 = material)\n";
    text += fmt::format("layer_thickness_mm {}\n", c_.layer_mm);
    text += fmt::format("slice_count {}\n", c_.total_layers);
    text += fmt::format("pixel_mm {} {}\n", c_.pitch_x_mm, c_.pitch_y_mm);
    text += fmt::format("material_count {}\n", c_.material_names.size());
    for (std::size_t j = 0; j < c_.material_names.size(); ++j)
      text += fmt::format("material {} {}\n", j + 1, c_.material_names[j]);
    for (int i = 0; i < c_.total_layers; ++i) {
      text += fmt::format("slice {}", i + 1);
      for (std::size_t j = 0; j < c_.material_names.size(); ++j)
        text += fmt::format(" {}", std::filesystem::path(file_name(i, j)).filename().string());
      text += "\n";
    }
    return text;
  }

  std::string file_name(int index, std::size_t material) const {
    return fmt::format("legacy/{}{}_{}.bmp", c_.prefix, layer_number(index, c_.total_layers),
                       c_.material_names[material]);
  }
  OutputContext c_;
};

}  // namespace

std::unique_ptr<LayerWriter> make_legacy_bitmap_writer(const OutputContext& context) {
  return std::make_unique<LegacyBitmapWriter>(context);
}

}  // namespace trivox::detail
