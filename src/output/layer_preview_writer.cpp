// `trivox slice --preview LAYERS`: chosen layers as PNGs for a person to look at. Unlike the
// Voxel Print images, each material shows in its opaque display colour and the pixels are
// square (the coarser axis is repeated: a J750 layer of W x H pixels becomes W x 2H), so a
// layer looks like the part; the files are indexed-colour PNGs, one palette entry per label.
#include <algorithm>

#include <fmt/format.h>

#include "output/nearest_resample.h"
#include "output/stack_writers.h"
#include "trivox/error.h"
#include "trivox/output/display_colours.h"
#include "trivox/output/png_io.h"

namespace trivox::detail {

namespace {

class LayerPreviewWriter final : public LayerWriter {
 public:
  LayerPreviewWriter(OutputContext c, std::vector<std::pair<int, int>> layers)
      : c_(std::move(c)), layers_(std::move(layers)) {
    palette_.push_back({c_.preview_background_rgba[0], c_.preview_background_rgba[1], c_.preview_background_rgba[2]});
    // Display colours: a material whose colour is nearly another's shows in a distinct one.
    for (const Rgb& m : display_colours(c_.material_rgba, c_.preview_background_rgba)) palette_.push_back(m);
    std::sort(layers_.begin(), layers_.end());
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "preview", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "preview").string(), ec.message()));
  }

  std::string_view name() const noexcept override { return "layer-preview"; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    const auto it = std::lower_bound(layers_.begin(), layers_.end(), std::pair<int, int>{index, 0});
    if (it == layers_.end() || it->first != index) return {};
    const int w0 = labels.width_px(), h0 = labels.height_px();
    const double pitch = std::min(c_.pitch_x_mm, c_.pitch_y_mm);
    const int w = resampled_count(w0, c_.pitch_x_mm, pitch), h = resampled_count(h0, c_.pitch_y_mm, pitch);
    // Label j is palette entry j (0 the background, j + 1 material j).
    std::vector<std::uint8_t> indices(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    const auto last = static_cast<std::uint8_t>(palette_.size() - 1);
    for (int y = 0; y < h; ++y) {
      const int sy = source_index(y, h, h0);
      for (int x = 0; x < w; ++x)
        indices[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
            std::min(labels.at(source_index(x, w, w0), sy), last);
    }
    const std::string file = fmt::format("preview/layer_{:05d}.png", it->second);
    write_png_indexed(c_.dir / file, w, h, indices, palette_, c_.png);
    return {file};
  }

 private:
  OutputContext c_;
  std::vector<std::pair<int, int>> layers_;           // (job index, model layer number), by index
  std::vector<std::array<std::uint8_t, 3>> palette_;  // index = label
};

}  // namespace

}  // namespace trivox::detail

namespace trivox {

std::unique_ptr<LayerWriter> make_layer_preview_writer(const OutputContext& context,
                                                       std::vector<std::pair<int, int>> layers) {
  return std::make_unique<detail::LayerPreviewWriter>(context, std::move(layers));
}

}  // namespace trivox
