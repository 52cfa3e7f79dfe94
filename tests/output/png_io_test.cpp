#include "trivox/output/png_io.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "trivox/error.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// A fresh empty folder per test, removed afterwards.
class PngTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("trivox_png_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ignored);
    fs::remove_all(dir_, ignored);
  }

  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    return names;
  }

  fs::path dir_;
};

std::vector<std::uint8_t> file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::uint32_t big_endian32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) | (std::uint32_t{b[at + 2]} << 8) |
         std::uint32_t{b[at + 3]};
}

// The IHDR chunk, which the PNG specification puts first, right after the signature.
struct Ihdr {
  std::uint32_t width, height;
  int bit_depth, color_type;
};
Ihdr read_ihdr(const fs::path& path) {
  const std::vector<std::uint8_t> b = file_bytes(path);
  EXPECT_GE(b.size(), 33u);
  if (b.size() < 33) return {};
  const std::array<std::uint8_t, 8> signature{137, 80, 78, 71, 13, 10, 26, 10};
  EXPECT_TRUE(std::equal(signature.begin(), signature.end(), b.begin()));
  EXPECT_EQ(big_endian32(b, 8), 13u);
  EXPECT_EQ(std::string(b.begin() + 12, b.begin() + 16), "IHDR");
  return {big_endian32(b, 16), big_endian32(b, 20), b[24], b[25]};
}

std::vector<std::uint8_t> random_bytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint8_t> v(n);
  for (std::uint8_t& b : v) b = static_cast<std::uint8_t>(rng() >> 24);
  return v;
}

// ---- hand-made PNGs for the reader: stored (uncompressed) deflate blocks, so the files are
// built here without zlib, independently of the writer under test.
std::uint32_t crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}
void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}
void put_chunk(std::vector<std::uint8_t>& out, const char* type, const std::vector<std::uint8_t>& data) {
  put32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put32(out, crc32(out.data() + start, out.size() - start));
}
// `filtered`: the scanlines, each already prefixed by its filter byte (0 here).
std::vector<std::uint8_t> make_png(std::uint32_t w, std::uint32_t h, int bit_depth, int color_type, int interlace,
                                   const std::vector<std::uint8_t>& filtered,
                                   const std::vector<std::uint8_t>& plte = {},
                                   const std::vector<std::uint8_t>& trns = {}) {
  std::vector<std::uint8_t> png{137, 80, 78, 71, 13, 10, 26, 10};
  std::vector<std::uint8_t> ihdr;
  put32(ihdr, w);
  put32(ihdr, h);
  ihdr.insert(ihdr.end(), {static_cast<std::uint8_t>(bit_depth), static_cast<std::uint8_t>(color_type), 0, 0,
                           static_cast<std::uint8_t>(interlace)});
  put_chunk(png, "IHDR", ihdr);
  if (!plte.empty()) put_chunk(png, "PLTE", plte);
  if (!trns.empty()) put_chunk(png, "tRNS", trns);
  std::vector<std::uint8_t> z{0x78, 0x01, 0x01};  // zlib header; one final stored block
  const auto n = static_cast<std::uint16_t>(filtered.size());
  z.insert(z.end(), {static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8), static_cast<std::uint8_t>(~n),
                     static_cast<std::uint8_t>(~n >> 8)});
  z.insert(z.end(), filtered.begin(), filtered.end());
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (std::uint8_t byte : filtered) {
    a = (a + byte) % 65521;
    b = (b + a) % 65521;
  }
  put32(z, (b << 16) | a);
  put_chunk(png, "IDAT", z);
  put_chunk(png, "IEND", {});
  return png;
}

TEST_F(PngTest, RgbaRoundTrip) {
  const RgbaImage image{37, 23, random_bytes(37 * 23 * 4, 1)};
  const fs::path path = dir_ / "slice.png";
  write_png_rgba(path, image);
  EXPECT_EQ(read_png_rgba(path), image);
  EXPECT_EQ(entries(), std::vector<std::string>{"slice.png"});  // no temporary left behind
}

TEST_F(PngTest, RgbaIsColourType6) {
  const fs::path path = dir_ / "slice.png";
  write_png_rgba(path, 300, 7, random_bytes(300 * 7 * 4, 2));
  const Ihdr ihdr = read_ihdr(path);
  EXPECT_EQ(ihdr.width, 300u);
  EXPECT_EQ(ihdr.height, 7u);
  EXPECT_EQ(ihdr.bit_depth, 8);
  EXPECT_EQ(ihdr.color_type, 6);
}

TEST_F(PngTest, Gray8RoundTrip) {
  const std::vector<std::uint8_t> gray = random_bytes(19 * 11, 3);
  const fs::path path = dir_ / "labels.png";
  write_png_gray8(path, 19, 11, gray);
  const Ihdr ihdr = read_ihdr(path);
  EXPECT_EQ(ihdr.bit_depth, 8);
  EXPECT_EQ(ihdr.color_type, 0);
  const RgbaImage back = read_png_rgba(path);
  ASSERT_EQ(back.width_px, 19);
  ASSERT_EQ(back.height_px, 11);
  for (std::size_t i = 0; i < gray.size(); ++i) {
    const std::array<std::uint8_t, 4> expected{gray[i], gray[i], gray[i], 255};
    ASSERT_TRUE(std::equal(expected.begin(), expected.end(), back.rgba.begin() + 4 * static_cast<std::ptrdiff_t>(i)))
        << "pixel " << i;
  }
}

TEST_F(PngTest, Gray1RoundTrip) {
  std::vector<std::uint8_t> values = random_bytes(13 * 5, 4);
  for (std::size_t i = 0; i < values.size(); i += 3) values[i] = 0;
  const fs::path path = dir_ / "mask.png";
  write_png_gray1(path, 13, 5, values);  // 13 is not a multiple of 8: a partial last byte
  const Ihdr ihdr = read_ihdr(path);
  EXPECT_EQ(ihdr.bit_depth, 1);
  EXPECT_EQ(ihdr.color_type, 0);
  const RgbaImage back = read_png_rgba(path);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint8_t v = values[i] != 0 ? 255 : 0;
    ASSERT_EQ(back.rgba[4 * i], v) << "pixel " << i;
    ASSERT_EQ(back.rgba[4 * i + 1], v);
    ASSERT_EQ(back.rgba[4 * i + 2], v);
    ASSERT_EQ(back.rgba[4 * i + 3], 255);
  }
}

TEST_F(PngTest, IndexedRoundTripsAtTheSmallestBitDepth) {
  // Palettes of 2, 3, 5, 16, 17 and 256 colours take 1, 2, 4, 4, 8 and 8 bits per pixel;
  // widths that are not multiples of the pixels per byte leave a partial last byte in every row.
  const std::array<std::pair<std::size_t, int>, 6> cases = {{{2, 1}, {3, 2}, {5, 4}, {16, 4}, {17, 8}, {256, 8}}};
  std::uint32_t seed = 20;
  for (const auto& [colours, bits] : cases) {
    std::vector<std::array<std::uint8_t, 3>> palette;
    const std::vector<std::uint8_t> rgb = random_bytes(3 * colours, seed++);
    for (std::size_t c = 0; c < colours; ++c) palette.push_back({rgb[3 * c], rgb[3 * c + 1], rgb[3 * c + 2]});
    std::vector<std::uint8_t> indices = random_bytes(13 * 6, seed++);
    for (std::uint8_t& i : indices) i = static_cast<std::uint8_t>(i % colours);
    const fs::path path = dir_ / "preview.png";
    write_png_indexed(path, 13, 6, indices, palette);
    const Ihdr ihdr = read_ihdr(path);
    EXPECT_EQ(ihdr.color_type, 3) << colours;
    EXPECT_EQ(ihdr.bit_depth, bits) << colours;
    const RgbaImage back = read_png_rgba(path);
    ASSERT_EQ(back.width_px, 13);
    ASSERT_EQ(back.height_px, 6);
    for (std::size_t i = 0; i < indices.size(); ++i) {
      const auto& c = palette[indices[i]];
      const std::array<std::uint8_t, 4> expected{c[0], c[1], c[2], 255};
      ASSERT_TRUE(std::equal(expected.begin(), expected.end(), back.rgba.begin() + 4 * static_cast<std::ptrdiff_t>(i)))
          << colours << " colours, pixel " << i;
    }
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"preview.png"});
}

TEST_F(PngTest, IndexedRefusesABadPaletteOrIndex) {
  const std::vector<std::array<std::uint8_t, 3>> two = {{0, 0, 0}, {255, 255, 255}};
  const std::vector<std::array<std::uint8_t, 3>> too_many(257, {1, 2, 3});
  const std::vector<std::uint8_t> indices = {0, 1, 1, 0, 2, 0};
  EXPECT_THROW(write_png_indexed(dir_ / "a.png", 3, 2, indices, std::span<const std::array<std::uint8_t, 3>>{}), Error);
  const std::vector<std::uint8_t> zeros(6, 0);
  EXPECT_THROW(write_png_indexed(dir_ / "a.png", 3, 2, zeros, too_many), Error);
  EXPECT_THROW(write_png_indexed(dir_ / "a.png", 2, 2, indices, two), Error);  // size mismatch
  try {
    write_png_indexed(dir_ / "a.png", 3, 2, indices, two);
    ADD_FAILURE() << "index 2 of a two-colour palette was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pixel (1, 1) has palette index 2"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(PngTest, EveryLevelAndFilterRoundTrips) {
  const RgbaImage image{41, 9, random_bytes(41 * 9 * 4, 5)};
  for (int level = 0; level <= 9; ++level) {
    for (PngFilter filter : {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp, PngFilter::kAverage, PngFilter::kPaeth,
                             PngFilter::kAdaptive}) {
      const fs::path path = dir_ / "a.png";
      write_png_rgba(path, image, PngWriteParams{level, filter});
      ASSERT_EQ(read_png_rgba(path), image) << "level " << level << ", " << to_string(filter);
    }
  }
}

// Each zlib strategy on a dithered-looking image (few colours in runs) and on noise.
TEST_F(PngTest, EveryStrategyRoundTrips) {
  std::vector<std::uint8_t> runs(53 * 17 * 4);
  for (std::size_t i = 0; i < runs.size(); ++i)
    runs[i] = static_cast<std::uint8_t>(((i / 4) % 7 < 3) ? 255 : 40 + i % 4);
  for (const RgbaImage& image : {RgbaImage{53, 17, runs}, RgbaImage{53, 17, random_bytes(53 * 17 * 4, 11)}}) {
    for (PngStrategy strategy :
         {PngStrategy::kDefault, PngStrategy::kFiltered, PngStrategy::kRle, PngStrategy::kHuffmanOnly}) {
      for (PngFilter filter : {PngFilter::kNone, PngFilter::kSub, PngFilter::kPaeth}) {
        const fs::path path = dir_ / "a.png";
        write_png_rgba(path, image, PngWriteParams{1, filter, strategy});
        ASSERT_EQ(read_png_rgba(path), image) << to_string(strategy) << ", " << to_string(filter);
      }
    }
  }
}

TEST_F(PngTest, ParamsOutsideTheirRangesNameTheField) {
  auto message = [](const PngWriteParams& params) {
    try {
      params.validate();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(PngWriteParams{10}).find("zlib_level = 10"), std::string::npos);
  EXPECT_NE(message(PngWriteParams{1, static_cast<PngFilter>(17)}).find("filter = 17"), std::string::npos);
  EXPECT_NE(message(PngWriteParams{1, PngFilter::kNone, static_cast<PngStrategy>(9)}).find("strategy = 9"),
            std::string::npos);
  EXPECT_EQ(message(PngWriteParams{}), "");
}

TEST_F(PngTest, WritingTwiceGivesIdenticalBytes) {
  const RgbaImage image{64, 32, random_bytes(64 * 32 * 4, 6)};
  for (const PngWriteParams& params : {PngWriteParams{}, PngWriteParams{6, PngFilter::kAdaptive}}) {
    write_png_rgba(dir_ / "a.png", image, params);
    write_png_rgba(dir_ / "b.png", image, params);
    EXPECT_EQ(file_bytes(dir_ / "a.png"), file_bytes(dir_ / "b.png"));
  }
}

TEST_F(PngTest, RowByRowWritesTheBytesOfTheWholeImage) {
  const RgbaImage image{37, 19, random_bytes(37 * 19 * 4, 12)};
  for (const PngWriteParams& params : {PngWriteParams{}, PngWriteParams{6, PngFilter::kAdaptive}}) {
    write_png_rgba(dir_ / "whole.png", image, params);
    std::vector<int> asked;
    write_png_rgba_rows(
        dir_ / "rows.png", image.width_px, image.height_px,
        [&](int y, std::span<std::uint8_t> row) {
          asked.push_back(y);
          ASSERT_EQ(row.size(), 37u * 4);
          std::copy_n(image.rgba.begin() + static_cast<std::ptrdiff_t>(y) * 37 * 4, 37 * 4, row.begin());
        },
        params);
    EXPECT_EQ(file_bytes(dir_ / "rows.png"), file_bytes(dir_ / "whole.png"));
    std::vector<int> in_order(19);
    std::iota(in_order.begin(), in_order.end(), 0);
    EXPECT_EQ(asked, in_order);
  }
}

TEST_F(PngTest, RowSourceThatThrowsLeavesNoFileAndSaysWhy) {
  const fs::path path = dir_ / "slice.png";
  const RgbaImage old_image{8, 8, random_bytes(256, 13)};
  write_png_rgba(path, old_image);
  const std::vector<std::uint8_t> old_bytes = file_bytes(path);
  try {
    write_png_rgba_rows(path, 8, 8, [](int y, std::span<std::uint8_t> row) {
      if (y == 5) throw Error("row 5 has no labels");
      std::fill(row.begin(), row.end(), std::uint8_t{7});
    });
    FAIL() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("row 5 has no labels"), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"slice.png"});
  EXPECT_EQ(file_bytes(path), old_bytes);
  EXPECT_THROW(write_png_rgba_rows(path, 0, 8, [](int, std::span<std::uint8_t>) {}), Error);
}

TEST_F(PngTest, OverwritesAnExistingFile) {
  const fs::path path = dir_ / "slice.png";
  write_png_rgba(path, RgbaImage{2, 2, random_bytes(16, 7)});
  const RgbaImage second{3, 1, random_bytes(12, 8)};
  write_png_rgba(path, second);
  EXPECT_EQ(read_png_rgba(path), second);
  EXPECT_EQ(entries().size(), 1u);
}

TEST_F(PngTest, UnwritableFolderThrowsIoErrorNamingThePath) {
  const RgbaImage image{4, 4, random_bytes(64, 9)};
  auto expect_io_error = [&](const fs::path& path) {
    try {
      write_png_rgba(path, image);
      ADD_FAILURE() << "no IoError for " << path;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  };
  expect_io_error(dir_ / "missing" / "slice.png");
  write_bytes(dir_ / "file", {1, 2, 3});
  expect_io_error(dir_ / "file" / "slice.png");  // the "folder" is a regular file
  expect_io_error(dir_);                         // a folder is in the way
  EXPECT_EQ(entries(), std::vector<std::string>{"file"});
}

TEST_F(PngTest, ReadOnlyFolderThrowsIoErrorNamingThePath) {
  const fs::path locked = dir_ / "locked";
  fs::create_directory(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(locked.c_str(), W_OK) == 0) {
    GTEST_SKIP() << "permissions are not enforced for this user (root?)";
  }
  const fs::path path = locked / "slice.png";
  try {
    write_png_rgba(path, RgbaImage{4, 4, random_bytes(64, 9)});
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_empty(locked));
}

// Running out of space mid-file (simulated with the file-size limit, which fails writes
// with EFBIG like a full disk fails them with ENOSPC): IoError, the temporary file removed,
// and the previous file under the final name untouched.
TEST_F(PngTest, FailedWriteLeavesThePreviousFile) {
  const fs::path path = dir_ / "slice.png";
  const RgbaImage old_image{8, 8, random_bytes(256, 10)};
  write_png_rgba(path, old_image);
  const std::vector<std::uint8_t> old_bytes = file_bytes(path);

  const RgbaImage big{512, 512, random_bytes(512 * 512 * 4, 11)};  // incompressible, 1 MiB
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = saved;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string message;
  try {
    write_png_rgba(path, big);
  } catch (const IoError& e) {
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_EQ(entries(), std::vector<std::string>{"slice.png"});
  EXPECT_EQ(file_bytes(path), old_bytes);
}

TEST_F(PngTest, RejectsBadArguments) {
  const fs::path path = dir_ / "a.png";
  auto is_plain_error = [&](auto&& write) {
    try {
      write();
    } catch (const IoError&) {
      return false;
    } catch (const Error&) {
      return true;
    }
    return false;
  };
  const std::vector<std::uint8_t> pixels(16 * 4);
  EXPECT_TRUE(is_plain_error([&] { write_png_rgba(path, 4, 3, pixels); }));  // 4x4 given
  EXPECT_TRUE(is_plain_error([&] { write_png_rgba(path, 0, 16, {}); }));
  EXPECT_TRUE(is_plain_error([&] { write_png_gray8(path, 16, -4, pixels); }));
  EXPECT_TRUE(is_plain_error([&] { write_png_gray1(path, 8, 7, pixels); }));
  EXPECT_TRUE(is_plain_error([&] { write_png_rgba(path, 4, 4, pixels, PngWriteParams{10}); }));
  EXPECT_TRUE(is_plain_error([&] {
    write_png_rgba(path, 4, 4, pixels, PngWriteParams{1, static_cast<PngFilter>(42)});
  }));
  EXPECT_TRUE(entries().empty());
}

TEST_F(PngTest, ReadRejectsMissingAndCorruptFiles) {
  auto expect_io_error = [](const fs::path& path) {
    try {
      read_png_rgba(path);
      ADD_FAILURE() << "no IoError for " << path;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  };
  expect_io_error(dir_ / "missing.png");
  write_bytes(dir_ / "text.png", {'n', 'o', 't', ' ', 'a', ' ', 'p', 'n', 'g'});
  expect_io_error(dir_ / "text.png");
  write_png_rgba(dir_ / "good.png", RgbaImage{30, 30, random_bytes(3600, 12)});
  std::vector<std::uint8_t> bytes = file_bytes(dir_ / "good.png");
  bytes.resize(bytes.size() / 2);
  write_bytes(dir_ / "truncated.png", bytes);
  expect_io_error(dir_ / "truncated.png");
}

// Files the writer never makes, built by hand: palette with transparency, 16-bit RGB, and
// an interlaced (Adam7) grayscale image.
TEST_F(PngTest, ReadsOtherFormatsAsRgba) {
  // 2-bit palette, 3 x 2: indices 0 1 2 / 3 2 1; entry 1 half transparent.
  const std::vector<std::uint8_t> plte{10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120};
  const std::vector<std::uint8_t> palette_rows{0, 0b00011000, 0, 0b11100100};
  write_bytes(dir_ / "palette.png", make_png(3, 2, 2, 3, 0, palette_rows, plte, {255, 128}));
  const RgbaImage palette = read_png_rgba(dir_ / "palette.png");
  EXPECT_EQ(palette.rgba, (std::vector<std::uint8_t>{10,  20,  30,  255, 40, 50, 60, 128, 70, 80, 90, 255,
                                                     100, 110, 120, 255, 70, 80, 90, 255, 40, 50, 60, 128}));

  // 16-bit RGB, 1 x 2: samples scaled to 8 bits with rounding (v / 257).
  const std::vector<std::uint8_t> rgb16_rows{0, 0xff, 0xff, 0x80, 0x00, 0x00, 0x00,
                                             0, 0x12, 0x34, 0x00, 0xff, 0xfe, 0x01};
  write_bytes(dir_ / "rgb16.png", make_png(1, 2, 16, 2, 0, rgb16_rows));
  const RgbaImage rgb16 = read_png_rgba(dir_ / "rgb16.png");
  EXPECT_EQ(rgb16.rgba, (std::vector<std::uint8_t>{255, 128, 0, 255, 18, 1, 253, 255}));

  // Adam7 gray, 3 x 3, pixel value = 10 * (3y + x). Passes (x0, y0, dx, dy): 1 (0,0,8,8),
  // 4 (2,0,4,4), 5 (0,2,2,4), 6 (1,0,2,2), 7 (0,1,1,2); passes 2 and 3 are empty.
  const std::vector<std::uint8_t> adam7{0, 0,            // pass 1: (0,0)
                                        0, 20,           // pass 4: (2,0)
                                        0, 60, 80,       // pass 5: (0,2) (2,2)
                                        0, 10,           // pass 6: (1,0)
                                        0, 70,           // pass 6: (1,2)
                                        0, 30, 40, 50};  // pass 7: row 1
  write_bytes(dir_ / "adam7.png", make_png(3, 3, 8, 0, 1, adam7));
  const RgbaImage gray = read_png_rgba(dir_ / "adam7.png");
  ASSERT_EQ(gray.rgba.size(), 36u);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(gray.rgba[static_cast<std::size_t>(4 * i)], 10 * i) << "pixel " << i;
    EXPECT_EQ(gray.rgba[static_cast<std::size_t>(4 * i + 3)], 255);
  }
}

}  // namespace
}  // namespace trivox
