// Greyscale outputs for masked-resin (LCD/DLP) printers (docs/FORMATS.md): "greyscale", a
// plain stack of 8-bit greyscale PNGs with their pixel size, and "sl1" / "sl1s", the print
// archives of the Prusa SL1 and SL1S.
//
// The archive is laid out as PrusaSlicer 2.5 writes it (`prusa-slicer --export-sla`, checked
// by tests/tools/check_sl1_archive.py): config.ini (the printer's job description),
// prusaslicer.ini (the settings, read back when the archive is imported), one 8-bit
// greyscale PNG per layer, `<jobDir><5-digit layer>.png` from 0, each the whole display in
// the orientation and mirroring of the printer profile, and the thumbnails. Each worker
// encodes its layer's PNG into a spool (layer_spool.h) and keeps the layer's exposed area;
// finish() zips everything in a fixed order with the deterministic zip writer, so the archive
// is the same bytes for any thread count and after --resume.
#include <algorithm>
#include <cmath>
#include <mutex>

#include <fmt/format.h>

#include "output/layer_spool.h"
#include "output/nearest_resample.h"
#include "output/stack_writers.h"
#include "output/zip_writer.h"
#include "trivox/error.h"
#include "trivox/output/atomic_file.h"
#include "trivox/version.h"

namespace trivox::detail {

namespace {

std::filesystem::path made_folder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", dir.string(), ec.message()));
  return dir;
}

// A number as PrusaSlicer writes it in its ini files: the shortest form that reads back.
std::string ini_number(double x) { return fmt::format("{}", x); }

class GreyscaleStackWriter final : public LayerWriter {
 public:
  explicit GreyscaleStackWriter(OutputContext c) : c_(std::move(c)) {
    made_folder(c_.dir / "greyscale");
    png_ = png_with_pixel_size(c_);
  }
  std::string_view name() const noexcept override { return "greyscale"; }
  bool takes_grey() const noexcept override { return true; }
  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    return write_grey_layer(index, labels, GreyImage());
  }
  std::vector<std::string> write_grey_layer(int index, const LabelImage& labels, const GreyImage& grey) const override {
    const GreyImage exposure = exposure_of(labels, grey);
    std::string file = "greyscale/" + c_.prefix + layer_number(index, c_.total_layers) + ".png";
    write_png_gray8(c_.dir / file, exposure.width_px(), exposure.height_px(), exposure.values(), png_);
    return {file};
  }

 private:
  OutputContext c_;
  PngWriteParams png_;
};

// Where a pixel of the layer bitmap lands in the archive's PNG, for PrusaSlicer's raster
// transformation: the display raster has x along the bed's x and y along its y (upwards);
// portrait turns it (the PNG is pixels_y wide: bed y runs along the PNG's width, bed x along
// its height), and the mirrors flip the result. PrusaSlicer flips y by default (so that the
// PNG's first row is the display's far edge) and, in portrait, x as well, undoing the mirror
// a turn implies (libslic3r/SLA/RasterBase.hpp, the Trafo of 2.5).
struct DisplayTrafo {
  int png_width = 0, png_height = 0;
  bool portrait = false, flip_x = false, flip_y = false;
  int offset_x = 0, offset_y = 0;  // display pixel of the bitmap's bottom-left pixel

  DisplayTrafo(const MaskedDisplay& d, int bitmap_w, int bitmap_h)
      : png_width(d.portrait ? d.pixels_y : d.pixels_x),
        png_height(d.portrait ? d.pixels_x : d.pixels_y),
        portrait(d.portrait),
        flip_x(d.portrait ? !d.mirror_x : d.mirror_x),
        flip_y(!d.mirror_y),
        // The bitmap centred on the display, as PrusaSlicer centres the model on the bed.
        offset_x((d.pixels_x - bitmap_w) / 2),
        offset_y((d.pixels_y - bitmap_h) / 2) {}

  // PNG column and row of bitmap pixel (col, row) of a bitmap `bitmap_h` rows tall.
  std::pair<int, int> png_of(int col, int row, int bitmap_h) const noexcept {
    const int x = offset_x + col;                   // along the bed's x
    const int y = offset_y + (bitmap_h - 1 - row);  // along the bed's y, upwards
    int a = portrait ? y : x, b = portrait ? x : y;
    if (flip_x) a = png_width - 1 - a;
    if (flip_y) b = png_height - 1 - b;
    return {a, b};
  }
};

class Sl1Writer final : public LayerWriter {
 public:
  Sl1Writer(OutputContext c, std::string format) : c_(std::move(c)), format_(std::move(format)) {
    if (!c_.printer.display)
      throw Error(
          fmt::format("{}: printer '{}' has no display: the {} archive needs a masked-resin printer profile "
                      "(sl1, sl1s, or one based on them)",
                      format_, c_.printer.name, format_));
    display_ = *c_.printer.display;
    std::string model = display_.printer_model;
    for (char& ch : model) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (model != format_)
      throw Error(fmt::format("{}: printer '{}' is an {}: write --format {}", format_, c_.printer.name,
                              display_.printer_model, model));
    if (c_.width_px > display_.pixels_x || c_.height_px > display_.pixels_y)
      throw Error(fmt::format("{}: the model's bitmap is {} x {} px but the {} display is {} x {} px ({} x {} mm)",
                              format_, c_.width_px, c_.height_px, display_.printer_model, display_.pixels_x,
                              display_.pixels_y, display_.width_mm, display_.height_mm));
    job_dir_ = c_.prefix;
    while (!job_dir_.empty() && job_dir_.back() == '_') job_dir_.pop_back();
    if (job_dir_.empty()) job_dir_ = "slice";
    made_folder(c_.dir / format_);
    spool_ = std::make_unique<LayerSpool>(c_.dir / format_ / ("stack." + format_ + ".spool"), c_.total_layers);
    exposed_.assign(static_cast<std::size_t>(c_.total_layers), 0);
    top_view_.assign(static_cast<std::size_t>(c_.width_px) * static_cast<std::size_t>(c_.height_px), 0);
    png_ = c_.png;  // no pHYs: as PrusaSlicer writes them
    png_.pixels_per_metre_x = png_.pixels_per_metre_y = 0;
  }
  std::string_view name() const noexcept override { return format_; }
  bool needs_whole_stack() const noexcept override { return true; }
  bool takes_grey() const noexcept override { return true; }
  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    return write_grey_layer(index, labels, GreyImage());
  }
  std::vector<std::string> write_grey_layer(int index, const LabelImage& labels, const GreyImage& grey) const override {
    const GreyImage exposure = exposure_of(labels, grey);
    const DisplayTrafo t(display_, exposure.width_px(), exposure.height_px());
    std::vector<std::uint8_t> png(static_cast<std::size_t>(t.png_width) * static_cast<std::size_t>(t.png_height), 0);
    std::int64_t exposed = 0;
    for (int row = 0; row < exposure.height_px(); ++row)
      for (int col = 0; col < exposure.width_px(); ++col) {
        const std::uint8_t g = exposure.at(col, row);
        if (g == 0) continue;
        ++exposed;
        const auto [a, b] = t.png_of(col, row, exposure.height_px());
        png[static_cast<std::size_t>(b) * static_cast<std::size_t>(t.png_width) + static_cast<std::size_t>(a)] = g;
      }
    spool_->put(index, encode_png_gray8(t.png_width, t.png_height, png, png_));
    std::lock_guard lock(mutex_);
    exposed_[static_cast<std::size_t>(index)] = exposed;
    for (std::size_t i = 0; i < top_view_.size() && i < exposure.values().size(); ++i)
      top_view_[i] = std::max(top_view_[i], exposure.values()[i]);
    return {};
  }

  StackCost stack_cost(const StackSampling& sampling) const override {
    std::lock_guard lock(mutex_);
    StackCost cost;
    cost.files = 1;
    cost.scratch_bytes = scaled_to_job(sampling, [&](int index) { return spool_->size(index); });
    const auto slices = static_cast<std::uint64_t>(sampling.model_layers + sampling.padded_layers);
    // Per entry a local header and a central record with its name; the ini files and the
    // thumbnails are a few kilobytes.
    cost.file_bytes = cost.scratch_bytes + slices * (76 + 2 * (job_dir_.size() + 9)) + 64 * 1024;
    cost.memory_bytes = top_view_.size() + static_cast<std::uint64_t>(display_.pixels_x) * display_.pixels_y * 2;
    return cost;
  }

  std::vector<std::string> finish() const override {
    std::lock_guard lock(mutex_);
    const std::string file = format_ + "/" + job_dir_ + "." + format_;
    const std::filesystem::path target = c_.dir / file;
    AtomicFile out(target);
    ZipWriter zip(out.file(), target.string());
    zip.add("config.ini", config_ini());
    zip.add("prusaslicer.ini", prusaslicer_ini());
    for (int i = 0; i < c_.total_layers; ++i) zip.add(fmt::format("{}{:05d}.png", job_dir_, i), spool_->get(i));
    zip.add("thumbnail/thumbnail400x400.png", thumbnail(400, 400));
    zip.add("thumbnail/thumbnail800x480.png", thumbnail(800, 480));
    zip.finish();
    out.commit();
    return {file};
  }

 private:
  double pixel_area_mm2() const { return c_.pitch_x_mm * c_.pitch_y_mm; }
  bool fast_layer(int i) const {
    const double area = static_cast<double>(exposed_[static_cast<std::size_t>(i)]) * pixel_area_mm2();
    return area <= display_.area_fill_percent / 100.0 * display_.width_mm * display_.height_mm;
  }
  // The exposure of layer i: the first three at the initial exposure, then `faded_layers`
  // stepping down to the exposure, as the printer runs them (and PrusaSlicer estimates).
  double layer_exposure_s(int i) const {
    if (i < 3) return display_.initial_exposure_s;
    const int fade = i - 3;
    if (fade < display_.faded_layers) {
      const double step = (display_.initial_exposure_s - display_.exposure_s) / (display_.faded_layers + 1);
      return display_.initial_exposure_s - (fade + 1) * step;
    }
    return display_.exposure_s;
  }

  std::string config_ini() const {
    int fast = 0;
    double seconds = 0, used_mm3 = 0;
    for (int i = 0; i < c_.total_layers; ++i) {
      const bool is_fast = fast_layer(i);
      fast += is_fast ? 1 : 0;
      seconds += layer_exposure_s(i) + (is_fast ? display_.fast_tilt_s : display_.slow_tilt_s);
      used_mm3 += static_cast<double>(exposed_[static_cast<std::size_t>(i)]) * pixel_area_mm2() * c_.layer_mm;
    }
    // Keys in PrusaSlicer's (alphabetical) order. fileCreationTimestamp is fixed so that the
    // archive depends only on the job.
    std::string x;
    x += "action = print\n";
    x += fmt::format("expTime = {}\n", ini_number(display_.exposure_s));
    x += fmt::format("expTimeFirst = {}\n", ini_number(display_.initial_exposure_s));
    x += "expUserProfile = 0\n";
    x += "fileCreationTimestamp = 1980-01-01 at 00:00:00 UTC\n";
    x += "hollow = 0\n";
    x += fmt::format("jobDir = {}\n", job_dir_);
    x += fmt::format("layerHeight = {}\n", ini_number(c_.layer_mm));
    // The resin the exposures are for (MaskedDisplay::resin), not the scene's materials, which
    // on a resin printer are grey levels of that one resin.
    x += fmt::format("materialName = {}\n", display_.resin.empty() ? "unnamed resin" : display_.resin);
    x += fmt::format("numFade = {}\n", display_.faded_layers);
    x += fmt::format("numFast = {}\n", fast);
    x += fmt::format("numSlow = {}\n", c_.total_layers - fast);
    x += fmt::format("printProfile = {} mm greyscale (trivox)\n", ini_number(c_.layer_mm));
    x += fmt::format("printTime = {:.6f}\n", seconds);
    x += fmt::format("printerModel = {}\n", display_.printer_model);
    x += fmt::format("printerProfile = {}\n", c_.printer.name);
    x += "printerVariant = default\n";
    x += fmt::format("prusaSlicerVersion = trivox-{}\n", version());
    x += fmt::format("usedMaterial = {:.6f}\n", used_mm3 / 1000.0);
    return x;
  }

  std::string prusaslicer_ini() const {
    const MaskedDisplay& d = display_;
    std::string x;
    x += fmt::format("area_fill = {}\n", ini_number(d.area_fill_percent));
    x += fmt::format("display_height = {}\n", ini_number(d.height_mm));
    x += fmt::format("display_mirror_x = {}\n", d.mirror_x ? 1 : 0);
    x += fmt::format("display_mirror_y = {}\n", d.mirror_y ? 1 : 0);
    x += fmt::format("display_orientation = {}\n", d.portrait ? "portrait" : "landscape");
    x += fmt::format("display_pixels_x = {}\n", d.pixels_x);
    x += fmt::format("display_pixels_y = {}\n", d.pixels_y);
    x += fmt::format("display_width = {}\n", ini_number(d.width_mm));
    x += fmt::format("exposure_time = {}\n", ini_number(d.exposure_s));
    x += fmt::format("faded_layers = {}\n", d.faded_layers);
    x += fmt::format("fast_tilt_time = {}\n", ini_number(d.fast_tilt_s));
    x += fmt::format("initial_exposure_time = {}\n", ini_number(d.initial_exposure_s));
    x += fmt::format("initial_layer_height = {}\n", ini_number(c_.layer_mm));
    x += fmt::format("layer_height = {}\n", ini_number(c_.layer_mm));
    x += fmt::format("printer_model = {}\n", d.printer_model);
    x += "printer_technology = SLA\n";
    x += "printer_variant = default\n";
    x += fmt::format("slow_tilt_time = {}\n", ini_number(d.slow_tilt_s));
    return x;
  }

  // A top view for the printer's screen: every pixel exposed in some layer, in PrusaSlicer's
  // default resin colour; the box of those pixels fitted into w x h with a margin of a twentieth
  // on each side, centred, at its proportions (square pixels), transparent around it.
  std::string thumbnail(int w, int h) const {
    std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, 0);
    const int bw = c_.width_px;
    int x_lo = bw, x_hi = -1, y_lo = c_.height_px, y_hi = -1;
    for (int y = 0; y < c_.height_px; ++y)
      for (int x = 0; x < bw; ++x)
        if (top_view_[static_cast<std::size_t>(y) * static_cast<std::size_t>(bw) + static_cast<std::size_t>(x)] != 0) {
          x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
          y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
        }
    if (x_hi >= 0) {
      const int cw = x_hi - x_lo + 1, ch = y_hi - y_lo + 1;
      const double scale = 0.9 * std::min(static_cast<double>(w) / cw, static_cast<double>(h) / ch);
      const int tw = std::clamp(static_cast<int>(std::lround(cw * scale)), 1, w);
      const int th = std::clamp(static_cast<int>(std::lround(ch * scale)), 1, h);
      const int x0 = (w - tw) / 2, y0 = (h - th) / 2;
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          const std::uint8_t g =
              top_view_[static_cast<std::size_t>(y_lo + source_index(y, th, ch)) * static_cast<std::size_t>(bw) +
                        static_cast<std::size_t>(x_lo + source_index(x, tw, cw))];
          if (g == 0) continue;
          std::uint8_t* p =
              rgba.data() +
              (static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x0 + x)) * 4;
          // #FF8040 scaled by the grey, opaque.
          p[0] = static_cast<std::uint8_t>(255 * g / 255);
          p[1] = static_cast<std::uint8_t>(128 * g / 255);
          p[2] = static_cast<std::uint8_t>(64 * g / 255);
          p[3] = 255;
        }
    }
    return encode_png_rgba(w, h, rgba, png_);
  }

  OutputContext c_;
  std::string format_;
  MaskedDisplay display_;
  std::string job_dir_;
  PngWriteParams png_;
  std::unique_ptr<LayerSpool> spool_;
  mutable std::mutex mutex_;
  mutable std::vector<std::int64_t> exposed_;   // per layer: exposed pixels
  mutable std::vector<std::uint8_t> top_view_;  // per bitmap pixel: the largest grey of any layer
};

}  // namespace

std::unique_ptr<LayerWriter> make_greyscale_stack_writer(const OutputContext& context) {
  return std::make_unique<GreyscaleStackWriter>(context);
}

std::unique_ptr<LayerWriter> make_sl1_writer(const OutputContext& context) {
  return std::make_unique<Sl1Writer>(context, "sl1");
}

std::unique_ptr<LayerWriter> make_sl1s_writer(const OutputContext& context) {
  return std::make_unique<Sl1Writer>(context, "sl1s");
}

}  // namespace trivox::detail
