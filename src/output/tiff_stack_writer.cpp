// The "tiff" output: every layer of the job as one page of a single multi-page TIFF,
// tiff/stack.tif, for viewers that read image stacks (Fiji/ImageJ, ParaView, napari).
//
// Pages must be in layer order, but layers finish in any order on several threads. Each
// worker deflates its layer (the expensive part, in parallel) and appends the compressed
// bytes to a spool file beside the stack, noting where they are; when the job completes,
// finish() copies the pages into the TIFF in layer order with TIFFWriteRawStrip, one page in
// memory at a time, and removes the spool. The compressed bytes depend only on the labels, so
// the file is the same for any thread count and schedule.
#include <tiffio.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <system_error>

#include <fmt/format.h>

#include "output/stack_writers.h"
#include "trivox/error.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/detail/tiff_stack.h"

namespace trivox {

namespace {

// libtiff reports errors through a handler; this one keeps the last message for the IoError.
struct TiffMessage {
  char text[512] = "";
};

int on_tiff_message(TIFF*, void* user_data, const char* module, const char* fmt, va_list ap) {
  auto* m = static_cast<TiffMessage*>(user_data);
  char body[400];
  std::vsnprintf(body, sizeof body, fmt, ap);
  std::snprintf(m->text, sizeof m->text, "%s: %s", module != nullptr ? module : "libtiff", body);
  return 1;  // handled: libtiff prints nothing
}

int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

// Why a stdio call failed, from errno (which a short write need not set).
std::string errno_reason(int error_number) {
  return error_number != 0 ? std::error_code(error_number, std::generic_category()).message()
                           : std::string("short write");
}

// A TIFF opened with our handlers, closed by the destructor.
class TiffFile {
 public:
  TiffFile(const std::filesystem::path& path, const char* mode) {
    TIFFOpenOptions* opts = TIFFOpenOptionsAlloc();
    TIFFOpenOptionsSetErrorHandlerExtR(opts, on_tiff_message, &message_);
    TIFFOpenOptionsSetWarningHandlerExtR(opts, on_tiff_warning, nullptr);
    tif_ = TIFFOpenExt(path.c_str(), mode, opts);
    TIFFOpenOptionsFree(opts);
    if (tif_ == nullptr) throw IoError(fmt::format("{}: cannot open as TIFF: {}", path.string(), message_.text));
  }
  ~TiffFile() {
    if (tif_ != nullptr) TIFFClose(tif_);
  }
  TiffFile(const TiffFile&) = delete;
  TiffFile& operator=(const TiffFile&) = delete;
  TIFF* get() const noexcept { return tif_; }
  const char* message() const noexcept { return message_.text; }
  void clear_message() noexcept { message_.text[0] = '\0'; }
  // Closes, reporting whether libtiff could flush everything.
  bool close() {
    TIFF* t = tif_;
    tif_ = nullptr;
    message_.text[0] = '\0';
    TIFFClose(t);
    return message_.text[0] == '\0';
  }

 private:
  TIFF* tif_ = nullptr;
  TiffMessage message_;
};

}  // namespace

int read_tiff_stack(const std::filesystem::path& path, const std::function<void(int, const LabelImage&)>& visit) {
  TiffFile tif(path, "r");
  int page = 0;
  do {
    std::uint32_t w = 0, h = 0;
    std::uint16_t bps = 0, spp = 1;
    TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &w);
    TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &h);
    TIFFGetField(tif.get(), TIFFTAG_BITSPERSAMPLE, &bps);
    TIFFGetFieldDefaulted(tif.get(), TIFFTAG_SAMPLESPERPIXEL, &spp);
    if (bps != 8 || spp != 1 || w == 0 || h == 0 || w > 1000000 || h > 1000000)
      throw IoError(fmt::format("{}: page {} is not an 8-bit one-sample image ({} x {} px, {} bits, {} samples)",
                                path.string(), page + 1, w, h, bps, spp));
    LabelImage labels(static_cast<int>(w), static_cast<int>(h), 0);
    std::size_t at = 0;
    for (std::uint32_t strip = 0; strip < TIFFNumberOfStrips(tif.get()); ++strip) {
      const tmsize_t n = TIFFReadEncodedStrip(tif.get(), strip, labels.values().data() + at,
                                              static_cast<tmsize_t>(labels.values().size() - at));
      if (n < 0)
        throw IoError(fmt::format("{}: page {} cannot be decoded: {}", path.string(), page + 1, tif.message()));
      at += static_cast<std::size_t>(n);
    }
    if (at != labels.values().size())
      throw IoError(
          fmt::format("{}: page {} holds {} of its {} pixels", path.string(), page + 1, at, labels.values().size()));
    visit(page, labels);
    ++page;
    // TIFFReadDirectory returns 0 both at the last page and on a broken directory; only the
    // latter reports an error.
    tif.clear_message();
    if (TIFFReadDirectory(tif.get()) != 1) {
      if (tif.message()[0] != '\0')
        throw IoError(
            fmt::format("{}: the directory after page {} is unreadable: {}", path.string(), page, tif.message()));
      return page;
    }
  } while (true);
}

namespace detail {

namespace {

class TiffStackWriter final : public LayerWriter {
 public:
  explicit TiffStackWriter(OutputContext c) : c_(std::move(c)) {
    std::error_code ec;
    std::filesystem::create_directories(c_.dir / "tiff", ec);
    if (ec) throw IoError(fmt::format("{}: cannot create folder: {}", (c_.dir / "tiff").string(), ec.message()));
    spool_path_ = c_.dir / "tiff" / "stack.tif.spool";
    spool_ = std::fopen(spool_path_.c_str(), "w+b");
    if (spool_ == nullptr) throw IoError(fmt::format("{}: cannot create the page spool", spool_path_.string()));
    pages_.resize(static_cast<std::size_t>(c_.total_layers));
  }
  ~TiffStackWriter() override {
    if (spool_ != nullptr) std::fclose(spool_);
    std::error_code ec;
    std::filesystem::remove(spool_path_, ec);
  }
  std::string_view name() const noexcept override { return "tiff"; }
  bool needs_whole_stack() const noexcept override { return true; }

  std::vector<std::string> write_layer(int index, const LabelImage& labels) const override {
    uLongf size = compressBound(static_cast<uLong>(labels.values().size()));
    std::vector<Bytef> packed(size);
    if (compress2(packed.data(), &size, labels.values().data(), static_cast<uLong>(labels.values().size()), 6) != Z_OK)
      throw Error(fmt::format("tiff: cannot compress layer {}", index + 1));
    std::lock_guard lock(mutex_);
    errno = 0;
    if (std::fseek(spool_, 0, SEEK_END) != 0 || std::fwrite(packed.data(), 1, size, spool_) != size)
      throw IoError(fmt::format("{}: cannot write the page spool: {}", spool_path_.string(), errno_reason(errno)));
    pages_[static_cast<std::size_t>(index)] = {spool_end_, static_cast<std::uint64_t>(size)};
    spool_end_ += size;
    width_ = labels.width_px();
    height_ = labels.height_px();
    return {};
  }

  // Pages as spooled, each with its directory: 16 entries of 12 bytes with their count and
  // link (198 bytes), the colour map (3 x 256 x 2 bytes) and the two resolutions (8 bytes
  // each), word-aligned.
  static constexpr std::uint64_t kPageOverheadBytes = 198 + 1536 + 16 + 2;

  StackCost stack_cost(const StackSampling& sampling) const override {
    std::lock_guard lock(mutex_);
    const auto page = [&](int index) {
      return index >= 0 && static_cast<std::size_t>(index) < pages_.size()
                 ? pages_[static_cast<std::size_t>(index)].size
                 : std::uint64_t{0};
    };
    StackCost cost;
    cost.files = 1;
    cost.scratch_bytes = scaled_to_job(sampling, page);
    cost.file_bytes = 8 + cost.scratch_bytes +
                      kPageOverheadBytes * static_cast<std::uint64_t>(sampling.model_layers + sampling.padded_layers);
    for (int index : sampling.model_samples)
      cost.memory_bytes = std::max(cost.memory_bytes, page(index));  // one page at a time
    return cost;
  }

  std::vector<std::string> finish() const override {
    std::lock_guard lock(mutex_);
    errno = 0;
    if (std::fflush(spool_) != 0)
      throw IoError(fmt::format("{}: cannot write the page spool: {}", spool_path_.string(), errno_reason(errno)));
    const std::string file = "tiff/stack.tif";
    const std::filesystem::path target = c_.dir / file;
    // libtiff writes the file itself: the atomic file gives it the temporary name, removes it
    // on failure and, once whole, syncs it and renames it over the target.
    AtomicFile atomic(target);
    const std::filesystem::path& temp = atomic.temporary();
    // Classic TIFF addresses 4 GiB; larger stacks become BigTIFF.
    const bool big = spool_end_ > (std::uint64_t{3} << 30);
    TiffFile tif(temp, big ? "w8" : "w");
    std::vector<std::uint16_t> red(256, 0), green(256, 0), blue(256, 0);
    const auto set_colour = [&](std::size_t i, const std::array<std::uint8_t, 4>& c) {
      red[i] = static_cast<std::uint16_t>(c[0] * 257);
      green[i] = static_cast<std::uint16_t>(c[1] * 257);
      blue[i] = static_cast<std::uint16_t>(c[2] * 257);
    };
    set_colour(0, c_.background_rgba);
    for (std::size_t j = 0; j < c_.material_rgba.size(); ++j) set_colour(j + 1, c_.material_rgba[j]);
    std::vector<unsigned char> page;
    for (int i = 0; i < c_.total_layers; ++i) {
      const auto [offset, size] = pages_[static_cast<std::size_t>(i)];
      if (size == 0) throw Error(fmt::format("tiff: layer {} never reached the TIFF writer", i + 1));
      page.resize(size);
      if (std::fseek(spool_, static_cast<long>(offset), SEEK_SET) != 0 ||
          std::fread(page.data(), 1, size, spool_) != size)
        throw IoError(fmt::format("{}: cannot read the page spool", spool_path_.string()));
      TIFF* t = tif.get();
      TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
      TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(width_));
      TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(height_));
      TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 8);
      TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
      TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_PALETTE);
      TIFFSetField(t, TIFFTAG_COLORMAP, red.data(), green.data(), blue.data());
      TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
      TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
      TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, static_cast<std::uint32_t>(height_));
      TIFFSetField(t, TIFFTAG_RESOLUTIONUNIT, RESUNIT_CENTIMETER);
      TIFFSetField(t, TIFFTAG_XRESOLUTION, static_cast<float>(10.0 / c_.pitch_x_mm));
      TIFFSetField(t, TIFFTAG_YRESOLUTION, static_cast<float>(10.0 / c_.pitch_y_mm));
      TIFFSetField(t, TIFFTAG_PAGENUMBER, static_cast<std::uint16_t>(std::min(i, 65535)),
                   static_cast<std::uint16_t>(std::min(c_.total_layers, 65535)));
      errno = 0;
      if (TIFFWriteRawStrip(t, 0, page.data(), static_cast<tmsize_t>(size)) < 0 || TIFFWriteDirectory(t) != 1) {
        const int error_number = errno;  // libtiff's message does not say why a write failed
        throw IoError(fmt::format("{}: cannot write page {}: {}{}", target.string(), i + 1, tif.message(),
                                  error_number != 0 ? " (" + errno_reason(error_number) + ")" : std::string()));
      }
    }
    errno = 0;
    if (!tif.close()) {
      const int error_number = errno;
      throw IoError(fmt::format("{}: cannot finish the TIFF{}", target.string(),
                                error_number != 0 ? ": " + errno_reason(error_number) : std::string()));
    }
    atomic.commit();
    return {file};
  }

 private:
  struct Page {
    std::uint64_t offset = 0, size = 0;
  };
  OutputContext c_;
  std::filesystem::path spool_path_;
  mutable std::mutex mutex_;
  mutable std::FILE* spool_ = nullptr;
  mutable std::uint64_t spool_end_ = 0;
  mutable std::vector<Page> pages_;
  mutable int width_ = 0, height_ = 0;
};

}  // namespace

std::unique_ptr<LayerWriter> make_tiff_stack_writer(const OutputContext& context) {
  return std::make_unique<TiffStackWriter>(context);
}

}  // namespace detail

}  // namespace trivox
