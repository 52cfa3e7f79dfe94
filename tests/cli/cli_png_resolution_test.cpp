// Every printer image carries its pixel size (docs/FORMATS.md): the Voxel Print PNGs, the
// material bitmaps and the PNGs inside the GrabCAD package have a pHYs chunk with the
// printer's resolution in pixels per metre, so that a viewer shows a 600 x 300 dpi layer at
// its true proportions. Read back with libpng itself.
#include <png.h>

#include <cstdio>
#include <cstring>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"
#include "cli_small_scene.h"
#include "output/zip_reader.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

struct Phys {
  bool present = false;
  png_uint_32 x = 0, y = 0;
  int unit = -1;
};

struct MemoryPng {
  const std::string* bytes;
  std::size_t at = 0;
};

extern "C" void read_from_memory(png_structp png, png_bytep out, png_size_t count) {
  auto* source = static_cast<MemoryPng*>(png_get_io_ptr(png));
  if (source->at + count > source->bytes->size()) png_error(png, "read past the end");
  std::memcpy(out, source->bytes->data() + source->at, count);
  source->at += count;
}

// The pHYs chunk of a PNG's bytes, as libpng reads it (the chunks before the image data).
Phys phys_of(const std::string& bytes) {
  Phys p;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  MemoryPng source{&bytes};
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    ADD_FAILURE() << "libpng could not read the PNG";
    return p;
  }
  png_set_read_fn(png, &source, read_from_memory);
  png_read_info(png, info);
  int unit = -1;
  p.present = png_get_pHYs(png, info, &p.x, &p.y, &unit) != 0;
  p.unit = unit;
  png_destroy_read_struct(&png, &info, nullptr);
  return p;
}

void expect_printer_resolution(const std::string& bytes, const std::string& what) {
  const Phys p = phys_of(bytes);
  ASSERT_TRUE(p.present) << what << " has no pHYs chunk";
  // 600 x 300 dpi: 600 / 0.0254 and 300 / 0.0254 pixels per metre, rounded.
  EXPECT_EQ(p.x, 23622u) << what;
  EXPECT_EQ(p.y, 11811u) << what;
  EXPECT_EQ(p.unit, PNG_RESOLUTION_METER) << what;
}

TEST(CliPngResolution, VoxelPrintBitmapAndPackagePngsCarryThePrintersResolution) {
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene({"VeroCyan", "VeroMagenta"}));
  const fs::path out = dir.path() / "out";
  const CliResult r =
      run_cli(fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q --format voxelprint,bitmaps,gcvf",
                          shell_quote(dir.path() / "box.json"), shell_quote(out)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_printer_resolution(read_text(out / "slice_00001.png"), "slice_00001.png");
  expect_printer_resolution(read_text(out / "slice_00002.png"), "slice_00002.png");
  expect_printer_resolution(read_text(out / "bitmaps" / "slice_00001_VeroCyan.png"),
                            "bitmaps/slice_00001_VeroCyan.png");
  expect_printer_resolution(read_text(out / "bitmaps" / "slice_00002_VeroMagenta.png"),
                            "bitmaps/slice_00002_VeroMagenta.png");
  const detail::ZipReader package(out / "gcvf" / "stack.gcvf");
  int pngs = 0;
  for (const auto& entry : package.entries()) {
    if (!entry.name.ends_with(".png")) continue;
    ++pngs;
    expect_printer_resolution(package.read(entry), "gcvf/stack.gcvf: " + entry.name);
  }
  EXPECT_EQ(pngs, 2);
}

// The chunk follows the printer profile's pitch, not a fixed 600 x 300 dpi.
TEST(CliPngResolution, TheDensityFollowsTheProfilesPitch) {
  ScratchDir dir;
  write_text(dir.path() / "box.json",
             small_box_scene(
                 {"VeroCyan"}, 4,
                 R"({"name": "coarse", "x_dpi": 300, "y_dpi": 150, "layer_thickness_mm": 0.027, "max_materials": 3})"));
  const fs::path out = dir.path() / "out";
  const CliResult r = run_cli(fmt::format("slice {} -o {} --layers 1:1 --min-layers 0 -q --format voxelprint",
                                          shell_quote(dir.path() / "box.json"), shell_quote(out)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Phys p = phys_of(read_text(out / "slice_00001.png"));
  ASSERT_TRUE(p.present);
  EXPECT_EQ(p.x, 11811u);
  EXPECT_EQ(p.y, 5906u);  // 150 / 0.0254 = 5905.5..., rounded
}

}  // namespace
}  // namespace trivox::test
