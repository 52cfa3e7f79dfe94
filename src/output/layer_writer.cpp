#include "trivox/output/layer_writer.h"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "output/material_bits.h"
#include "output/stack_writers.h"
#include "trivox/error.h"

namespace trivox {

std::vector<std::string> write_layer_to(const LayerWriter& writer, int index, const LabelImage& labels,
                                        const GreyImage& grey) {
  return writer.takes_grey() ? writer.write_grey_layer(index, labels, grey) : writer.write_layer(index, labels);
}

GreyImage exposure_of(const LabelImage& labels, const GreyImage& grey) {
  if (grey.width_px() == labels.width_px() && grey.height_px() == labels.height_px() && !grey.values().empty())
    return grey;
  GreyImage out(labels.width_px(), labels.height_px(), 0);
  std::transform(labels.values().begin(), labels.values().end(), out.values().begin(),
                 [](std::uint8_t l) { return static_cast<std::uint8_t>(l != LabelImage::kVoid ? 255 : 0); });
  return out;
}

std::string layer_number(int index, int total_layers) {
  const int digits = std::max(5, static_cast<int>(fmt::format("{}", total_layers).size()));
  return fmt::format("{:0{}d}", index + 1, digits);
}

std::uint64_t scaled_to_job(const StackSampling& sampling, const std::function<std::uint64_t(int)>& per_layer) {
  std::uint64_t total = 0;
  if (!sampling.model_samples.empty() && sampling.model_layers > 0) {
    std::uint64_t sum = 0;
    for (int index : sampling.model_samples) sum += per_layer(index);
    const auto n = static_cast<std::uint64_t>(sampling.model_samples.size());
    total += (sum * static_cast<std::uint64_t>(sampling.model_layers) + n - 1) / n;  // rounded up
  }
  if (sampling.padding_sample >= 0 && sampling.padded_layers > 0)
    total += per_layer(sampling.padding_sample) * static_cast<std::uint64_t>(sampling.padded_layers);
  return total;
}

namespace detail {

PngWriteParams png_with_pixel_size(const OutputContext& context) {
  PngWriteParams png = context.png;
  png.pixels_per_metre_x = pixels_per_metre(context.pitch_x_mm);
  png.pixels_per_metre_y = pixels_per_metre(context.pitch_y_mm);
  return png;
}

std::array<std::uint8_t, 4> opaque(std::array<std::uint8_t, 4> rgba) {
  rgba[3] = 255;
  return rgba;
}

std::vector<std::array<std::uint8_t, 4>> voxelprint_palette(const OutputContext& context) {
  // Printer images are opaque: a material's alpha (its transparency) is shown in previews
  // only, as the public Voxel Print packages do.
  std::vector<std::array<std::uint8_t, 4>> palette = {opaque(context.background_rgba)};
  for (const auto& c : context.material_rgba) palette.push_back(opaque(c));
  // Colour-exact output needs one distinct colour per material and for the background.
  for (std::size_t a = 0; a < palette.size(); ++a)
    for (std::size_t b = a + 1; b < palette.size(); ++b)
      if (palette[a] == palette[b])
        throw Error(fmt::format(
            "Voxel Print output needs a distinct colour for every material and for the background (opaque: the "
            "alpha is not part of the image colour), but {} and {} are both #{:02X}{:02X}{:02X}",
            a == 0 ? std::string("the background") : "material '" + context.material_names[a - 1] + "'",
            "material '" + context.material_names[b - 1] + "'", palette[a][0], palette[a][1], palette[a][2]));
  return palette;
}

void voxelprint_rgba_row(const LabelImage& labels, int y, const std::vector<std::array<std::uint8_t, 4>>& palette,
                         std::span<std::uint8_t> rgba) {
  std::uint8_t* out = rgba.data();
  for (std::uint8_t label : labels.row(y)) {
    std::memcpy(out, palette[label].data(), 4);
    out += 4;
  }
}

std::vector<std::uint8_t> voxelprint_rgba(const LabelImage& labels,
                                          const std::vector<std::array<std::uint8_t, 4>>& palette) {
  std::vector<std::uint8_t> rgba(labels.values().size() * 4);
  const std::size_t row_bytes = static_cast<std::size_t>(labels.width_px()) * 4;
  for (int y = 0; y < labels.height_px(); ++y)
    voxelprint_rgba_row(labels, y, palette,
                        std::span(rgba).subspan(static_cast<std::size_t>(y) * row_bytes, row_bytes));
  return rgba;
}

}  // namespace detail

namespace {

class VoxelPrintWriter final : public LayerWriter {
 public:
  explicit VoxelPrintWriter(OutputContext c)
      : c_(std::move(c)), palette_(detail::voxelprint_palette(c_)), png_(detail::png_with_pixel_size(c_)) {}
  std::string_view name() const noexcept override { return "voxelprint"; }
  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    std::string file = c_.prefix + layer_number(index, c_.total_layers) + ".png";
    // Row by row: a layer's RGBA (tens of megabytes at printer resolution) never exists whole.
    write_png_rgba_rows(
        c_.dir / file, labels.width_px(), labels.height_px(),
        [&](int y, std::span<std::uint8_t> row) { detail::voxelprint_rgba_row(labels, y, palette_, row); }, png_);
    return {file};
  }

 private:
  OutputContext c_;
  std::vector<std::array<std::uint8_t, 4>> palette_;  // index = label
  PngWriteParams png_;                                // with the printer's pixel size (pHYs)
};

class MaterialBitmapWriter final : public LayerWriter {
 public:
  explicit MaterialBitmapWriter(OutputContext c) : c_(std::move(c)), png_(detail::png_with_pixel_size(c_)) {}
  std::string_view name() const noexcept override { return "bitmaps"; }
  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    std::vector<std::string> files;
    detail::for_each_material_bits(
        labels, c_.material_names.size(), [&](std::size_t j, const std::vector<std::uint8_t>& bits) {
          std::string file =
              fmt::format("bitmaps/{}{}_{}.png", c_.prefix, layer_number(index, c_.total_layers), c_.material_names[j]);
          write_png_gray1(c_.dir / file, labels.width_px(), labels.height_px(), bits, png_);
          files.push_back(std::move(file));
        });
    return files;
  }

 private:
  OutputContext c_;
  PngWriteParams png_;  // with the printer's pixel size (pHYs)
};

std::unique_ptr<LayerWriter> make_bitmaps_writer(const OutputContext& context) {
  std::error_code ec;
  std::filesystem::create_directories(context.dir / "bitmaps", ec);
  if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (context.dir / "bitmaps").string(), ec.message()));
  return std::make_unique<MaterialBitmapWriter>(context);
}

// The registry: every output format by name, in the order the program lists them. A new
// format is one row here (and its writer).
struct LayerWriterFormat {
  std::string_view name;
  std::unique_ptr<LayerWriter> (*make)(const OutputContext&);
  bool stack;                            // what its writers' needs_whole_stack() says
  bool names_files_by_material = false;  // bitmaps and legacy name their files after the materials
  bool voxel_print = false;              // what GrabCAD Voxel Print reads (its stacks have a minimum height)
  bool greys = false;                    // what its writers' takes_grey() says: grey levels, not materials
};
constexpr LayerWriterFormat kLayerWriterFormats[] = {
    {"voxelprint",
     [](const OutputContext& c) -> std::unique_ptr<LayerWriter> { return std::make_unique<VoxelPrintWriter>(c); },
     false, false, true},
    {"bitmaps", make_bitmaps_writer, false, true},
    {"legacy", detail::make_legacy_bitmap_writer, false, true},
    {"tiff", detail::make_tiff_stack_writer, true},
    {"vdb", detail::make_vdb_writer, true},
    {"gcvf", detail::make_gcvf_writer, true, false, true},
    {"greyscale", detail::make_greyscale_stack_writer, false, false, false, true},
    {"sl1", detail::make_sl1_writer, true, false, false, true},
    {"sl1s", detail::make_sl1s_writer, true, false, false, true},
    {"preview", detail::make_preview_writer, true},
};

}  // namespace

std::unique_ptr<LayerWriter> make_layer_writer(std::string_view format, const OutputContext& context) {
  for (const LayerWriterFormat& f : kLayerWriterFormats)
    if (f.name == format) return f.make(context);
  throw Error(fmt::format("unknown output format '{}' (known: {})", format, fmt::join(layer_writer_names(), ", ")));
}

bool is_stack_format(std::string_view format) {
  for (const LayerWriterFormat& f : kLayerWriterFormats)
    if (f.name == format) return f.stack;
  throw Error(fmt::format("unknown output format '{}' (known: {})", format, fmt::join(layer_writer_names(), ", ")));
}

bool layer_writer_names_files_by_material(std::string_view format) {
  for (const LayerWriterFormat& f : kLayerWriterFormats)
    if (f.name == format) return f.names_files_by_material;
  return false;
}

bool layer_writer_feeds_voxel_print(std::string_view format) {
  for (const LayerWriterFormat& f : kLayerWriterFormats)
    if (f.name == format) return f.voxel_print;
  return false;
}

bool layer_writer_writes_greys(std::string_view format) {
  for (const LayerWriterFormat& f : kLayerWriterFormats)
    if (f.name == format) return f.greys;
  return false;
}

std::optional<std::string> file_name_part_problem(std::string_view text) {
  if (text.size() > kMaxFileNamePartBytes)
    return fmt::format("it is {} bytes long, and at most {} go into a file name", text.size(), kMaxFileNamePartBytes);
  if (text.find('/') != std::string_view::npos) return std::string("it holds '/', a folder separator");
  if (text.find('\\') != std::string_view::npos) return std::string("it holds '\\', a folder separator on Windows");
  if (text.find("..") != std::string_view::npos) return std::string("it holds \"..\", the parent folder");
  if (const auto c = first_control_character(text)) return fmt::format("it holds the control character 0x{:02X}", *c);
  return std::nullopt;
}

std::vector<std::string> layer_writer_names() {
  std::vector<std::string> names;
  for (const LayerWriterFormat& f : kLayerWriterFormats) names.emplace_back(f.name);
  return names;
}

}  // namespace trivox
