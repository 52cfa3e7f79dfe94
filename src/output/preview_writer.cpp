// The "preview" output: a contact sheet of downscaled layers and three orthogonal cuts
// through the stack, for a person to check a job at a glance.
//
// Memory stays bounded whatever the number of layers: while layers arrive (in any order,
// from several threads) the writer keeps only a thumbnail of each layer on the sheet (at
// most 64), one row and one column of every layer (for the x-z and y-z cuts) and the middle
// layer (the x-y cut). Everything is resampled by nearest neighbour from label images, so
// the files depend only on the labels: the same for any thread count or order. The images
// are indexed-colour PNGs: one palette entry per label, and the grid's grey.
#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>

#include <fmt/format.h>

#include "output/nearest_resample.h"
#include "output/stack_writers.h"
#include "trivox/error.h"
#include "trivox/output/display_colours.h"
#include "trivox/output/png_io.h"

namespace trivox::detail {

namespace {

constexpr int kMaxSheetLayers = 64;
constexpr int kThumbSidePx = 160;        // longer side of a thumbnail
constexpr std::uint8_t kGridGray = 128;  // lines between thumbnails

class PreviewWriter final : public LayerWriter {
 public:
  explicit PreviewWriter(OutputContext c) : c_(std::move(c)) {
    palette_.push_back({c_.preview_background_rgba[0], c_.preview_background_rgba[1], c_.preview_background_rgba[2]});
    // Display colours: a material whose colour is nearly another's shows in a distinct one.
    for (const Rgb& m : display_colours(c_.material_rgba, c_.preview_background_rgba)) palette_.push_back(m);
    grid_index_ = static_cast<std::uint8_t>(palette_.size());
    palette_.push_back({kGridGray, kGridGray, kGridGray});
    const int n = std::max(1, c_.model_layers);
    sheet_count_ = std::min(kMaxSheetLayers, n);
    for (int i = 0; i < sheet_count_; ++i) sheet_layers_.push_back(source_index(i, sheet_count_, n));
    thumbs_.resize(static_cast<std::size_t>(sheet_count_));
    middle_layer_ = n / 2;
    rows_.resize(static_cast<std::size_t>(n));
    cols_.resize(static_cast<std::size_t>(n));
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "preview", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "preview").string(), ec.message()));
  }

  std::string_view name() const noexcept override { return "preview"; }
  bool needs_whole_stack() const noexcept override { return true; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    if (index >= c_.model_layers) return {};  // padding layers are empty: nothing to show
    const int w = labels.width_px(), h = labels.height_px();
    std::vector<std::uint8_t> row(labels.row(h / 2).begin(), labels.row(h / 2).end());
    std::vector<std::uint8_t> col(static_cast<std::size_t>(h));
    for (int y = 0; y < h; ++y) col[static_cast<std::size_t>(y)] = labels.at(w / 2, y);
    std::optional<LabelImage> thumb;
    const auto sheet_slot = std::find(sheet_layers_.begin(), sheet_layers_.end(), index);
    if (sheet_slot != sheet_layers_.end()) thumb = downscale(labels);
    std::lock_guard lock(mutex_);
    width_ = w;
    height_ = h;
    rows_[static_cast<std::size_t>(index)] = std::move(row);
    cols_[static_cast<std::size_t>(index)] = std::move(col);
    if (thumb) thumbs_[static_cast<std::size_t>(sheet_slot - sheet_layers_.begin())] = std::move(*thumb);
    if (index == middle_layer_) middle_ = labels;
    return {};
  }

  // The four images' pixels (4 bytes each) bound their PNGs, which hold them compressed (an
  // upper bound: flat colours compress well); while the job runs the writer keeps a row and
  // a column of each model layer, the thumbnails and the middle layer.
  StackCost stack_cost(const StackSampling& sampling) const override {
    std::lock_guard lock(mutex_);
    StackCost cost;
    cost.files = 4;
    if (width_ == 0 || thumbs_.empty()) return cost;
    const int n = std::max(1, sampling.model_layers);
    const double wx = width_ * c_.pitch_x_mm, wy = height_ * c_.pitch_y_mm;
    const double thumb_pitch = std::max(wx, wy) / kThumbSidePx;
    const auto tw = static_cast<std::uint64_t>(resampled_count(width_, c_.pitch_x_mm, thumb_pitch));
    const auto th = static_cast<std::uint64_t>(resampled_count(height_, c_.pitch_y_mm, thumb_pitch));
    const auto cols = static_cast<std::uint64_t>(std::ceil(std::sqrt(static_cast<double>(sheet_count_))));
    const std::uint64_t rows = (static_cast<std::uint64_t>(sheet_count_) + cols - 1) / cols;
    const auto iso = [&](int count, double pitch) {
      return static_cast<std::uint64_t>(resampled_count(count, pitch, iso_pitch()));
    };
    const std::uint64_t images[] = {
        (cols * (tw + 1) + 1) * (rows * (th + 1) + 1), iso(width_, c_.pitch_x_mm) * iso(height_, c_.pitch_y_mm),
        iso(width_, c_.pitch_x_mm) * iso(n, c_.layer_mm), iso(height_, c_.pitch_y_mm) * iso(n, c_.layer_mm)};
    std::uint64_t largest = 0;
    for (const std::uint64_t pixels : images) {
      cost.file_bytes += 4 * pixels + 1024;  // and the file's headers
      largest = std::max(largest, 4 * pixels);
    }
    const auto w = static_cast<std::uint64_t>(width_), h = static_cast<std::uint64_t>(height_);
    // The rows, columns, thumbnails and middle layer collected, and one image being encoded.
    cost.memory_bytes =
        (w + h) * static_cast<std::uint64_t>(n) + static_cast<std::uint64_t>(sheet_count_) * tw * th + w * h + largest;
    return cost;
  }

  std::vector<std::string> finish() const override {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < rows_.size(); ++i)
      if (rows_[i].empty()) throw Error(fmt::format("preview: layer {} never reached the preview writer", i + 1));
    std::vector<std::string> files;
    files.push_back(write_sheet());
    files.push_back(write_cut_xy());
    files.push_back(write_cut("preview/cut_xz.png", rows_, c_.pitch_x_mm));
    files.push_back(write_cut("preview/cut_yz.png", cols_, c_.pitch_y_mm));
    return files;
  }

 private:
  // The common pitch of every preview image: the coarsest of the three, so that no image is
  // larger than the stack it shows in any direction.
  double iso_pitch() const { return std::max({c_.pitch_x_mm, c_.pitch_y_mm, c_.layer_mm}); }

  LabelImage downscale(const LabelImage& labels) const {
    const double wx = labels.width_px() * c_.pitch_x_mm, wy = labels.height_px() * c_.pitch_y_mm;
    const double pitch = std::max(wx, wy) / kThumbSidePx;
    const int tw = resampled_count(labels.width_px(), c_.pitch_x_mm, pitch);
    const int th = resampled_count(labels.height_px(), c_.pitch_y_mm, pitch);
    LabelImage t(tw, th, LabelImage::kVoid);
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x)
        t.at(x, y) = labels.at(source_index(x, tw, labels.width_px()), source_index(y, th, labels.height_px()));
    return t;
  }

  // The palette entry of a label: the label itself (0 the background, j + 1 material j).
  std::uint8_t colour_of(std::uint8_t label) const { return std::min<std::uint8_t>(label, grid_index_ - 1); }

  std::string write_sheet() const {
    const int tw = thumbs_.front().width_px(), th = thumbs_.front().height_px();
    const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(sheet_count_))));
    const int rows = (sheet_count_ + cols - 1) / cols;
    const int W = cols * (tw + 1) + 1, H = rows * (th + 1) + 1;
    std::vector<std::uint8_t> indices(static_cast<std::size_t>(W) * static_cast<std::size_t>(H), grid_index_);
    for (int i = 0; i < sheet_count_; ++i) {
      const LabelImage& t = thumbs_[static_cast<std::size_t>(i)];
      const int x0 = 1 + (i % cols) * (tw + 1), y0 = 1 + (i / cols) * (th + 1);
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x)
          indices[static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x0 + x)] =
              colour_of(t.at(x, y));
    }
    const std::string file = "preview/contact_sheet.png";
    write_png_indexed(c_.dir / file, W, H, indices, palette_, c_.png);
    return file;
  }

  std::string write_cut_xy() const {
    const int w = resampled_count(width_, c_.pitch_x_mm, iso_pitch());
    const int h = resampled_count(height_, c_.pitch_y_mm, iso_pitch());
    std::vector<std::uint8_t> indices(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        indices[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
            colour_of(middle_.at(source_index(x, w, width_), source_index(y, h, height_)));
    const std::string file = "preview/cut_xy.png";
    write_png_indexed(c_.dir / file, w, h, indices, palette_, c_.png);
    return file;
  }

  // A vertical cut: one line of each layer, the top layer at the top of the image.
  std::string write_cut(const std::string& file, const std::vector<std::vector<std::uint8_t>>& lines,
                        double pitch) const {
    const int n = static_cast<int>(lines.front().size()), layers = static_cast<int>(lines.size());
    const int w = resampled_count(n, pitch, iso_pitch());
    const int h = resampled_count(layers, c_.layer_mm, iso_pitch());
    std::vector<std::uint8_t> indices(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    for (int y = 0; y < h; ++y) {
      const auto& line = lines[static_cast<std::size_t>(layers - 1 - source_index(y, h, layers))];
      for (int x = 0; x < w; ++x)
        indices[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
            colour_of(line[static_cast<std::size_t>(source_index(x, w, n))]);
    }
    write_png_indexed(c_.dir / file, w, h, indices, palette_, c_.png);
    return file;
  }

  OutputContext c_;
  std::vector<std::array<std::uint8_t, 3>> palette_;  // index = label, then the grid's grey
  std::uint8_t grid_index_ = 0;
  int sheet_count_ = 0;
  std::vector<int> sheet_layers_;  // model layers on the sheet, ascending
  int middle_layer_ = 0;

  mutable std::mutex mutex_;
  mutable int width_ = 0, height_ = 0;
  mutable std::vector<LabelImage> thumbs_;               // per sheet slot
  mutable std::vector<std::vector<std::uint8_t>> rows_;  // middle row of each layer
  mutable std::vector<std::vector<std::uint8_t>> cols_;  // middle column of each layer
  mutable LabelImage middle_;
};

}  // namespace

std::unique_ptr<LayerWriter> make_preview_writer(const OutputContext& context) {
  return std::make_unique<PreviewWriter>(context);
}

}  // namespace trivox::detail
