// The "gcvf" output: a GrabCAD Voxel Print package, gcvf/stack.gcvf - the job's Voxel Print
// PNGs and a ConfigFile.xml that gives their resolution, size, count and material colours,
// in one zip archive (docs/FORMATS.md, "GrabCAD Voxel Print package" names the public
// sources of the layout and every field).
//
// Each worker encodes its layer's PNG exactly as the "voxelprint" output does (same palette,
// same encoder, same settings: the entries are byte for byte the voxelprint files) and
// spools it (layer_spool.h) with its per-material voxel counts; when the job completes,
// finish() zips the PNGs in layer order and the configuration after them, through an
// AtomicFile. The zip container is deterministic (zip_writer.h), so the package depends
// only on the layers and the settings.
#include <algorithm>
#include <cmath>
#include <mutex>

#include <fmt/format.h>

#include "output/layer_spool.h"
#include "output/stack_writers.h"
#include "output/zip_writer.h"
#include "trivox/error.h"
#include "trivox/output/atomic_file.h"
#include "trivox/printer/material_library.h"

namespace trivox::detail {

namespace {

std::string xml_escaped(std::string_view text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += ch;
    }
  }
  return out;
}

std::string rgba_text(const std::array<std::uint8_t, 4>& c) {
  return fmt::format("{} {} {} {}", c[0], c[1], c[2], c[3]);
}

// GCVF gives resolutions in whole dots per inch: the pitch must be 25.4 mm over a whole
// number (to a part in a million).
int whole_dpi(double pitch_mm, const char* axis) {
  const double dpi = 25.4 / pitch_mm;
  const double rounded = std::round(dpi);
  if (!(rounded >= 1) || std::abs(dpi - rounded) > 1e-6 * rounded)
    throw Error(
        fmt::format("gcvf: the {} pitch {} mm is not a whole number of dots per inch ({} dpi); GCVF records "
                    "whole dpi",
                    axis, pitch_mm, dpi));
  return static_cast<int>(rounded);
}

class GcvfWriter final : public LayerWriter {
 public:
  explicit GcvfWriter(OutputContext c)
      : c_(std::move(c)), palette_(voxelprint_palette(c_)), png_(png_with_pixel_size(c_)) {
    x_dpi_ = whole_dpi(c_.pitch_x_mm, "x");
    y_dpi_ = whole_dpi(c_.pitch_y_mm, "y");
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "gcvf", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "gcvf").string(), ec.message()));
    spool_ = std::make_unique<LayerSpool>(c_.dir / "gcvf" / "stack.gcvf.spool", c_.total_layers);
    counts_.assign(static_cast<std::size_t>(c_.total_layers), std::vector<std::int64_t>(palette_.size(), 0));
  }
  std::string_view name() const noexcept override { return "gcvf"; }
  bool needs_whole_stack() const noexcept override { return true; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    const std::vector<std::uint8_t> rgba = voxelprint_rgba(labels, palette_);
    const std::string png = encode_png_rgba(labels.width_px(), labels.height_px(), rgba, png_);
    std::vector<std::int64_t> count(palette_.size(), 0);
    for (std::uint8_t l : labels.values())
      if (l < count.size()) ++count[l];
    spool_->put(index, png);
    std::lock_guard lock(mutex_);
    counts_[static_cast<std::size_t>(index)] = std::move(count);  // a layer fed again replaces its count
    width_ = labels.width_px();
    height_ = labels.height_px();
    return {};
  }

  // The package is the spooled PNGs, a local header (30 bytes) and a central directory entry
  // (46 bytes) per entry, each with the entry's name, the configuration and the end record.
  StackCost stack_cost(const StackSampling& sampling) const override {
    std::lock_guard lock(mutex_);
    StackCost cost;
    cost.files = 1;
    cost.scratch_bytes = scaled_to_job(sampling, [&](int index) { return spool_->size(index); });
    const auto slices = static_cast<std::uint64_t>(sampling.model_layers + sampling.padded_layers);
    const std::uint64_t name_bytes = image_name(c_.total_layers - 1).size();
    // Voxel counts of the whole stack have up to 15 digits; the samples' fewer.
    const std::uint64_t config = config_xml().size() + 16 * c_.material_names.size();
    std::uint64_t extras = 0;
    for (const auto& [member, bytes] : c_.gcvf.extras) extras += bytes.size() + 30 + 46 + 2 * member.size();
    cost.file_bytes =
        cost.scratch_bytes + slices * (30 + 46 + 2 * name_bytes) + config + 2 * 14 + 30 + 46 + 22 + extras;
    std::uint64_t largest_png = 0;
    for (int index : sampling.model_samples) largest_png = std::max(largest_png, spool_->size(index));
    cost.memory_bytes = largest_png + slices * palette_.size() * sizeof(std::int64_t);  // one PNG, the voxel counts
    return cost;
  }

  std::vector<std::string> finish() const override {
    std::lock_guard lock(mutex_);
    const std::string file = "gcvf/stack.gcvf";
    const std::filesystem::path target = c_.dir / file;
    AtomicFile out(target);
    ZipWriter zip(out.file(), target.string());
    for (int i = 0; i < c_.total_layers; ++i) zip.add(image_name(i), spool_->get(i));
    zip.add("ConfigFile.xml", config_xml());
    for (const auto& [member, bytes] : c_.gcvf.extras) zip.add(member, bytes);
    zip.finish();
    out.commit();
    return {file};
  }

 private:
  // Slices are numbered from StartIndex (0) without padding, as the public packages do.
  std::string image_name(int index) const { return fmt::format("{}{}.png", c_.prefix, index); }

  // The name ConfigFile.xml gives material j: its Stratasys code where one is known and
  // wanted, else the scene's name.
  std::string material_name(std::size_t j) const {
    if (c_.gcvf.material_codes && j < c_.material_library.size() && !c_.material_library[j].empty())
      if (const auto m = find_library_material(c_.material_library[j]); m && !m->code.empty())
        return std::string(m->code);
    return c_.material_names[j];
  }

  std::string config_xml() const {
    std::vector<std::int64_t> total(palette_.size(), 0);
    for (const auto& layer : counts_)
      for (std::size_t l = 0; l < layer.size(); ++l) total[l] += layer[l];
    std::string x;
    x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    x += "<!-- GCVF: GrabCAD Voxel Print package written by trivox -->\n";
    x += "<GCVF>\n";
    x += "    <Version>2</Version>\n";
    x += "    <Resolution>\n";
    x += fmt::format("        <XDpi>{}</XDpi>\n", x_dpi_);
    x += fmt::format("        <YDpi>{}</YDpi>\n", y_dpi_);
    x += fmt::format("        <SliceThicknessNanoMeter>{}</SliceThicknessNanoMeter>\n",
                     static_cast<long long>(std::llround(c_.layer_mm * 1e6)));
    x += "    </Resolution>\n";
    x += "    <SliceDimensions>\n";
    x += fmt::format("        <SliceWidth>{}</SliceWidth>\n", width_);
    x += fmt::format("        <SliceHeight>{}</SliceHeight>\n", height_);
    x += "    </SliceDimensions>\n";
    x += "    <SliceRange>\n";
    x += "        <StartIndex>0</StartIndex>\n";
    x += fmt::format("        <NumberOfSlices>{}</NumberOfSlices>\n", c_.total_layers);
    x += "    </SliceRange>\n";
    x += "    <BitDepth>4</BitDepth>\n";
    x += "    <MaxNumberOfColors>6</MaxNumberOfColors>\n";
    x += "    <DataSemantics>Materials</DataSemantics>\n";
    x += "    <CreationMode>MODEL_ONLY</CreationMode>\n";
    x += fmt::format("    <ImageFilePrefix>{}</ImageFilePrefix>\n", xml_escaped(c_.prefix));
    x += "    <MaterialList>\n";
    x += fmt::format("        <BackGroundMaterialRGBA>{}</BackGroundMaterialRGBA>\n", rgba_text(palette_[0]));
    for (std::size_t j = 0; j < c_.material_names.size(); ++j) {
      if (c_.gcvf.omit_unused && total[j + 1] == 0) continue;  // as the later public writer does
      x += "        <Material>\n";
      x += fmt::format("            <Name>{}</Name>\n", xml_escaped(material_name(j)));
      x += fmt::format("            <RGBA>{}</RGBA>\n", rgba_text(palette_[j + 1]));
      x += fmt::format("            <VoxelCount>{}</VoxelCount>\n", total[j + 1]);
      x += "        </Material>\n";
    }
    x += "    </MaterialList>\n";
    x += "</GCVF>\n";
    return x;
  }

  OutputContext c_;
  std::vector<std::array<std::uint8_t, 4>> palette_;  // index = label
  PngWriteParams png_;                                // the Voxel Print PNGs, with the printer's pixel size (pHYs)
  int x_dpi_ = 0, y_dpi_ = 0;
  std::unique_ptr<LayerSpool> spool_;
  mutable std::mutex mutex_;
  mutable std::vector<std::vector<std::int64_t>> counts_;  // [layer][label]
  mutable int width_ = 0, height_ = 0;
};

}  // namespace

std::unique_ptr<LayerWriter> make_gcvf_writer(const OutputContext& context) {
  return std::make_unique<GcvfWriter>(context);
}

}  // namespace trivox::detail
