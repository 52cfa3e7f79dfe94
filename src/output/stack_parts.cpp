#include "trivox/output/detail/stack_parts.h"

#include <algorithm>
#include <cstdint>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/output/png_io.h"

namespace trivox::detail {

namespace {

constexpr std::string_view kLabelsSuffix = ".labels.png", kGreySuffix = ".grey.png";

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

class StackPartsWriter final : public LayerWriter {
 public:
  explicit StackPartsWriter(OutputContext c) : c_(std::move(c)) {}
  std::string_view name() const noexcept override { return "stack parts"; }
  bool takes_grey() const noexcept override { return true; }
  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    return write_grey_layer(index, labels, GreyImage());
  }
  std::vector<std::string> write_grey_layer(int index, const LabelImage& labels, const GreyImage& grey) const override {
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / kStackPartsFolder, ec);  // a failure shows in the write
    const std::string stem = std::string(kStackPartsFolder) + c_.prefix + layer_number(index, c_.total_layers);
    std::vector<std::string> files{stem + std::string(kLabelsSuffix)};
    write_png_gray8(c_.dir / files[0], labels.width_px(), labels.height_px(), labels.values(), c_.png);
    if (!grey.values().empty()) {
      files.push_back(stem + std::string(kGreySuffix));
      write_png_gray8(c_.dir / files[1], grey.width_px(), grey.height_px(), grey.values(), c_.png);
    }
    return files;
  }

 private:
  OutputContext c_;
};

// The grey plane of a PNG that must be width x height (its red channel: a grey PNG reads as
// R = G = B).
std::vector<std::uint8_t> grey_plane(const std::filesystem::path& path, int width_px, int height_px) {
  const RgbaImage im = read_png_rgba(path);
  if (im.width_px != width_px || im.height_px != height_px)
    throw IoError(fmt::format("{}: a stack part of {} x {} px, the job's layers are {} x {}", path.string(),
                              im.width_px, im.height_px, width_px, height_px));
  std::vector<std::uint8_t> plane(static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px));
  for (std::size_t i = 0; i < plane.size(); ++i) plane[i] = im.rgba[4 * i];
  return plane;
}

}  // namespace

std::unique_ptr<LayerWriter> make_stack_parts_writer(const OutputContext& context) {
  return std::make_unique<StackPartsWriter>(context);
}

bool is_stack_part(std::string_view name) { return name.substr(0, kStackPartsFolder.size()) == kStackPartsFolder; }

StackPart read_stack_part(const std::filesystem::path& dir, const std::vector<std::string>& names, int width_px,
                          int height_px, int materials) {
  StackPart part;
  bool labels_found = false;
  for (const std::string& name : names) {
    if (!is_stack_part(name)) continue;
    const std::filesystem::path path = dir / name;
    if (ends_with(name, kLabelsSuffix)) {
      std::vector<std::uint8_t> plane = grey_plane(path, width_px, height_px);
      if (const auto top = std::max_element(plane.begin(), plane.end());
          top != plane.end() && static_cast<int>(*top) > materials)
        throw IoError(fmt::format("{}: label {} in a stack part of a job of {} materials", path.string(),
                                  static_cast<int>(*top), materials));
      part.labels = LabelImage(width_px, height_px);
      std::copy(plane.begin(), plane.end(), part.labels.values().begin());
      labels_found = true;
    } else if (ends_with(name, kGreySuffix)) {
      std::vector<std::uint8_t> plane = grey_plane(path, width_px, height_px);
      part.grey = GreyImage(width_px, height_px);
      std::copy(plane.begin(), plane.end(), part.grey.values().begin());
    }
  }
  if (!labels_found)
    throw IoError(
        fmt::format("{}: no {}*{} among the layer's stack parts", dir.string(), kStackPartsFolder, kLabelsSuffix));
  return part;
}

}  // namespace trivox::detail
