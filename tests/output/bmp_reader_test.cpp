// The 1-bit BMP reader `verify` decodes the legacy bitmaps with: it gives back every pixel the
// legacy writer encoded, for widths on and off the byte and row-padding boundaries, reads
// top-down bitmaps too, and refuses what is not such a bitmap, naming the file and the field.
#include "trivox/output/detail/bmp_image.h"

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "output/stack_writers.h"
#include "trivox/error.h"

namespace trivox {
namespace {

std::vector<std::uint8_t> pattern(int w, int h) {
  std::vector<std::uint8_t> bits(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      bits[static_cast<std::size_t>(y * w + x)] = static_cast<std::uint8_t>((x * 3 + y * 5 + x * y) % 7 < 3);
  return bits;
}

TEST(BmpReader, DecodesEveryPixelTheLegacyWriterEncodes) {
  for (const int w : {1, 7, 8, 9, 31, 32, 33, 100}) {
    for (const int h : {1, 2, 5}) {
      SCOPED_TRACE(testing::Message() << w << " x " << h);
      const std::vector<std::uint8_t> bits = pattern(w, h);
      const std::string bmp = detail::encode_bmp1(w, h, bits.data(), 0.0423333, 0.0846667);
      const Bmp1Image im = decode_bmp1(bmp, "test.bmp");
      EXPECT_EQ(im.width_px, w);
      EXPECT_EQ(im.height_px, h);
      EXPECT_EQ(im.bits, bits);
      EXPECT_EQ(im.pixels_per_metre_x, 23622u);
      EXPECT_EQ(im.pixels_per_metre_y, 11811u);
    }
  }
}

TEST(BmpReader, ReadsTopDownRows) {
  const int w = 13, h = 4;
  const std::vector<std::uint8_t> bits = pattern(w, h);
  std::string bmp = detail::encode_bmp1(w, h, bits.data(), 0.1, 0.1);
  // Negative height: the same rows stored top row first.
  const std::size_t offset = 62, stride = 4;
  std::string flipped = bmp.substr(0, offset);
  for (int row = h - 1; row >= 0; --row) flipped += bmp.substr(offset + static_cast<std::size_t>(row) * stride, stride);
  const std::int32_t negative = -h;
  for (int i = 0; i < 4; ++i)
    flipped[22 + static_cast<std::size_t>(i)] =
        static_cast<char>((static_cast<std::uint32_t>(negative) >> (8 * i)) & 0xff);
  EXPECT_EQ(decode_bmp1(flipped, "top-down.bmp").bits, bits);
}

TEST(BmpReader, RefusesWhatIsNotAOneBitBitmapNamingTheField) {
  const std::vector<std::uint8_t> bits = pattern(20, 3);
  const std::string good = detail::encode_bmp1(20, 3, bits.data(), 0.1, 0.1);
  const auto changed = [&](std::size_t at, char value) {
    std::string b = good;
    b[at] = value;
    return b;
  };
  const struct {
    std::string bytes;
    std::string what;
  } cases[] = {
      {"", "not a BMP"},
      {changed(0, 'X'), "not a BMP"},
      {good.substr(0, good.size() - 1), "BMP header says"},
      {changed(28, 8), "bits per pixel"},
      {changed(26, 2), "planes"},
      {changed(30, 1), "compression"},
      {changed(46, 3), "palette"},
      {changed(10, 20), "overlaps the headers"},
      {changed(18, 0), "size 0 x 3"},
      {changed(23, 1), "does not fit"},  // 259 rows
  };
  for (const auto& c : cases) {
    try {
      (void)decode_bmp1(c.bytes, "bad.bmp");
      FAIL() << "accepted, expected: " << c.what;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.bmp"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace trivox
