// Volume images and textures: the readers, the wrap modes and the sampling, against values
// computed by hand.
#include "trivox/material/detail/volume_texture.h"

#include <gtest/gtest.h>
#include <tiffio.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "material/material_test_util.h"
#include "trivox/error.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "trivox_texture_tests";
  fs::create_directories(dir);
  return dir / name;
}

void write_bytes(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

// An image of nx x ny x nz, one channel, from values listed x fastest.
std::shared_ptr<const VolumeImage> image(int nx, int ny, int nz, std::vector<float> values, int channels = 1) {
  auto im = std::make_shared<VolumeImage>();
  im->nx = nx;
  im->ny = ny;
  im->nz = nz;
  im->channels = channels;
  im->values = std::move(values);
  return im;
}

float sample1(const VolumeTexture& t, Vec3 p) {
  float out[64];
  t.sample(p, out);
  return out[0];
}

TEST(VolumeTexture, WrapModes) {
  // n = 3: indices ... -4 -3 -2 -1 | 0 1 2 | 3 4 5 ...
  EXPECT_EQ(wrap_index(-2, 3, TextureWrap::kClamp), 0);
  EXPECT_EQ(wrap_index(5, 3, TextureWrap::kClamp), 2);
  EXPECT_EQ(wrap_index(-1, 3, TextureWrap::kRepeat), 2);
  EXPECT_EQ(wrap_index(-4, 3, TextureWrap::kRepeat), 2);
  EXPECT_EQ(wrap_index(4, 3, TextureWrap::kRepeat), 1);
  // Mirror: 0 1 2 2 1 0 0 1 2 ... and to the left -1 -> 0, -2 -> 1, -3 -> 2, -4 -> 2.
  EXPECT_EQ(wrap_index(3, 3, TextureWrap::kMirror), 2);
  EXPECT_EQ(wrap_index(5, 3, TextureWrap::kMirror), 0);
  EXPECT_EQ(wrap_index(6, 3, TextureWrap::kMirror), 0);
  EXPECT_EQ(wrap_index(-1, 3, TextureWrap::kMirror), 0);
  EXPECT_EQ(wrap_index(-2, 3, TextureWrap::kMirror), 1);
  EXPECT_EQ(wrap_index(-4, 3, TextureWrap::kMirror), 2);
  EXPECT_EQ(wrap_index(0, 1, TextureWrap::kMirror), 0);
  EXPECT_EQ(wrap_index(-7, 1, TextureWrap::kRepeat), 0);
}

// Two samples along x, 0 at x-centre 1/4 and 1 at x-centre 3/4.
TEST(VolumeTexture, SamplingByHand) {
  const auto im = image(2, 1, 1, {0.0f, 1.0f});
  TextureSampling nearest;
  nearest.filter = TextureFilter::kNearest;
  const VolumeTexture n(im, nearest);
  EXPECT_EQ(sample1(n, {0.49, 0.5, 0.5}), 0.0f);
  EXPECT_EQ(sample1(n, {0.5, 0.5, 0.5}), 1.0f);
  EXPECT_EQ(sample1(n, {1.0, 0.5, 0.5}), 1.0f);  // clamp at the far edge

  const VolumeTexture clamp(im, TextureSampling{});
  EXPECT_FLOAT_EQ(sample1(clamp, {0.25, 0.5, 0.5}), 0.0f);
  EXPECT_FLOAT_EQ(sample1(clamp, {0.375, 0.5, 0.5}), 0.25f);  // s = 0.25 between the centres
  EXPECT_FLOAT_EQ(sample1(clamp, {0.5, 0.5, 0.5}), 0.5f);
  EXPECT_FLOAT_EQ(sample1(clamp, {0.0, 0.5, 0.5}), 0.0f);  // beyond the first centre: the edge value
  EXPECT_FLOAT_EQ(sample1(clamp, {1.0, 0.5, 0.5}), 1.0f);

  TextureSampling repeat;
  repeat.wrap = {TextureWrap::kRepeat, TextureWrap::kClamp, TextureWrap::kClamp};
  const VolumeTexture r(im, repeat);
  EXPECT_FLOAT_EQ(sample1(r, {0.0, 0.5, 0.5}), 0.5f);     // halfway between the last and the first
  EXPECT_FLOAT_EQ(sample1(r, {0.125, 0.5, 0.5}), 0.25f);  // s = -0.25: 0.25 of sample 1, 0.75 of sample 0
  TextureSampling mirror = repeat;
  mirror.wrap[0] = TextureWrap::kMirror;
  const VolumeTexture mi(im, mirror);
  EXPECT_FLOAT_EQ(sample1(mi, {0.0, 0.5, 0.5}), 0.0f);  // the mirror image of sample 0 meets it

  // Repeats: two copies across [0, 1]; 0.625 is 0.25 into the second copy.
  TextureSampling twice = repeat;
  twice.repeats = {2.0, 1.0, 1.0};
  twice.filter = TextureFilter::kNearest;
  const VolumeTexture t2(im, twice);
  EXPECT_EQ(sample1(t2, {0.125, 0.5, 0.5}), 0.0f);
  EXPECT_EQ(sample1(t2, {0.375, 0.5, 0.5}), 1.0f);
  EXPECT_EQ(sample1(t2, {0.625, 0.5, 0.5}), 0.0f);
}

TEST(VolumeTexture, TrilinearCentreIsTheMeanAnd2dImagesAreConstantInW) {
  const auto cube = image(2, 2, 2, {1, 2, 3, 4, 5, 6, 7, 8});
  const VolumeTexture t(cube, TextureSampling{});
  EXPECT_FLOAT_EQ(sample1(t, {0.5, 0.5, 0.5}), 4.5f);
  // At x-centre of sample 0, y halfway, z at the centre of slice 1: (5 + 7) / 2.
  EXPECT_FLOAT_EQ(sample1(t, {0.25, 0.5, 0.75}), 6.0f);

  const auto flat = image(2, 2, 1, {0, 1, 2, 3});
  const VolumeTexture f(flat, TextureSampling{});
  for (double w : {0.0, 0.3, 0.999, 1.0}) EXPECT_FLOAT_EQ(sample1(f, {0.5, 0.5, w}), 1.5f) << w;
}

TEST(VolumeTexture, MaterialMapsChannelsAndTheCellDomain) {
  // Two channels: channel 0 -> material 1, channel 1 ignored (void).
  const auto im = image(2, 1, 1, {0.2f, 0.9f, 0.6f, 0.9f}, 2);
  TextureSampling s;
  s.filter = TextureFilter::kNearest;
  const TextureMaterial m(VolumeTexture(im, s), {1, kVoidMaterial}, 3, ParamBox{{0, 0, 0}, {4, 1, 1}});
  // The cell's u in [0, 4] maps to [0, 1]: u = 1 is 0.25 (sample 0), u = 3 is 0.75 (sample 1).
  EXPECT_EQ(test::eval_one(m, {1, 0.5, 0.5}), (std::vector<float>{0.0f, 0.2f, 0.0f}));
  EXPECT_EQ(test::eval_one(m, {3, 0.5, 0.5}), (std::vector<float>{0.0f, 0.6f, 0.0f}));
  EXPECT_THROW(TextureMaterial(VolumeTexture(im, s), {0, 0}, 3, kUnitParamBox), Error);
  EXPECT_THROW(TextureMaterial(VolumeTexture(im, s), {0, 1, 2}, 3, kUnitParamBox), Error);
  EXPECT_THROW(TextureMaterial(VolumeTexture(im, s), {5}, 3, kUnitParamBox), Error);
  TextureSampling bad;
  bad.repeats = {0.0, 1.0, 1.0};
  EXPECT_THROW(VolumeTexture(im, bad), Error);
  EXPECT_THROW(VolumeTexture(image(2, 1, 1, {0.0f}), s), Error);  // too few values
}

TEST(VolumeImageFiles, RawByTypeAndByteOrder) {
  const fs::path u8 = scratch("u8.raw");
  write_bytes(u8, std::string("\x00\xff\x33\x66", 4));
  const VolumeImage a = read_raw_volume(u8, {2, 1, 2, 1, RawSampleType::kUint8, false});
  EXPECT_EQ(a.values, (std::vector<float>{0.0f, 1.0f, 0x33 / 255.0f, 0x66 / 255.0f}));
  EXPECT_FLOAT_EQ(a.at(0, 0, 1, 0), 0x33 / 255.0f);

  const fs::path u16 = scratch("u16.raw");
  write_bytes(u16, std::string("\x12\x34\xff\xff", 4));
  EXPECT_FLOAT_EQ(read_raw_volume(u16, {1, 1, 1, 2, RawSampleType::kUint16, true}).values[0], 0x1234 / 65535.0f);
  EXPECT_FLOAT_EQ(read_raw_volume(u16, {1, 1, 1, 2, RawSampleType::kUint16, false}).values[0], 0x3412 / 65535.0f);

  const fs::path f32 = scratch("f32.raw");
  const float values[2] = {0.75f, -2.5f};
  std::string bytes(8, '\0');
  std::memcpy(bytes.data(), values, 8);  // the test machine's order: little-endian
  write_bytes(f32, bytes);
  EXPECT_EQ(read_raw_volume(f32, {2, 1, 1, 1, RawSampleType::kFloat32, false}).values,
            (std::vector<float>{0.75f, -2.5f}));

  try {
    read_raw_volume(u8, {2, 2, 2, 1, RawSampleType::kUint8, false});
    ADD_FAILURE() << "no error for a short file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 4 bytes but 2 x 2 x 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_raw_volume(scratch("missing.raw"), {1, 1, 1, 1, RawSampleType::kUint8, false}), IoError);
}

// A two-page 16-bit grey TIFF written with libtiff: two z slices of 3 x 2.
TEST(VolumeImageFiles, MultiPageTiff) {
  const fs::path path = scratch("stack.tif");
  {
    TIFF* t = TIFFOpen(path.string().c_str(), "w");
    ASSERT_NE(t, nullptr);
    for (std::uint16_t page = 0; page < 2; ++page) {
      TIFFSetField(t, TIFFTAG_IMAGEWIDTH, 3u);
      TIFFSetField(t, TIFFTAG_IMAGELENGTH, 2u);
      TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
      TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 16);
      TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
      TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
      TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, 1u);
      for (std::uint32_t y = 0; y < 2; ++y) {
        std::uint16_t row[3];
        for (std::uint16_t x = 0; x < 3; ++x) row[x] = static_cast<std::uint16_t>(1000 * page + 100 * y + x);
        ASSERT_GE(TIFFWriteScanline(t, row, y, 0), 0);
      }
      TIFFWriteDirectory(t);
    }
    TIFFClose(t);
  }
  const VolumeImage im = read_tiff_volume(path);
  EXPECT_EQ(im.nx, 3);
  EXPECT_EQ(im.ny, 2);
  EXPECT_EQ(im.nz, 2);
  EXPECT_EQ(im.channels, 1);
  EXPECT_FLOAT_EQ(im.at(2, 1, 1, 0), 1102 / 65535.0f);
  EXPECT_FLOAT_EQ(im.at(1, 0, 0, 0), 1 / 65535.0f);
  write_bytes(scratch("not.tif"), "plain text");
  EXPECT_THROW(read_tiff_volume(scratch("not.tif")), IoError);
}

}  // namespace
}  // namespace trivox
