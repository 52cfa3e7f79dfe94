// The greyscale outputs for masked-resin printers (src/output/greyscale_writers.cpp):
//   - "greyscale": one 8-bit greyscale PNG per layer, the layer's grey image pixel for pixel,
//     with its pixel size in pHYs;
//   - "sl1s" (and "sl1"): a Prusa archive whose layer images are the grey images laid on the
//     whole display, turned and mirrored as the printer profile says (checked here against the
//     transformation worked out from the profile; tests/tools/check_sl1_archive.py checks it
//     against PrusaSlicer's own archive), with config.ini and prusaslicer.ini describing the
//     job and the printer, and the thumbnails;
//   - both the same bytes for one and three threads and after a stop and resume, and verified
//     by `trivox verify`.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/detail/gcvf_package.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// A long bar (20 x 2 mm) and a small block (2 x 2 mm) beside its end at x = 0, 1 mm tall,
// graded along x so the greys vary: an image turned or mirrored the wrong way shows it.
// `resin`: more keys of the greyscale block (",\"exposure_s\": 3", ...).
Scene bars_scene(const std::string& printer, const std::string& resin = "") {
  const std::string json = fmt::format(R"({{
    "units": "mm", "printer": "{}",
    "materials": [{{ "name": "stiff", "rgba": [255, 128, 64] }}, {{ "name": "soft", "rgba": [64, 128, 255] }}],
    "greyscale": {{ "source": {{ "material": "stiff" }}, "curve": [[0, 60], [1, 250]], "antialiasing": 2 {} }},
    "cells": [
      {{ "name": "bar", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
         "points": [[0,0,0],[20,0,0],[0,2,0],[20,2,0],[0,0,1],[20,0,1],[0,2,1],[20,2,1]] }},
        "material": {{ "kind": "expression", "fractions": {{ "stiff": "u", "soft": "1 - u" }} }} }},
      {{ "name": "block", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
         "points": [[0,5,0],[2,5,0],[0,7,0],[2,7,0],[0,5,1],[2,5,1],[0,7,1],[2,7,1]] }},
        "material": "stiff" }}
    ]
  }})",
                                       printer, resin);
  return parse_scene(json, fs::temp_directory_path() / "bars.json");
}

JobParams resin_params(const std::string& name, const std::vector<std::string>& formats, int threads = 2) {
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-resin-{}-{}", ::getpid(), name);
  fs::remove_all(p.output_dir);
  p.formats = formats;
  p.threads = threads;
  p.min_layers = 0;
  p.manifest_interval_seconds = 0;
  return p;
}

std::map<std::string, std::string> archive_members(const fs::path& path) {
  std::map<std::string, std::string> out;
  const std::string cmd = fmt::format(
      "python3 -c \"import sys,zipfile,base64; z=zipfile.ZipFile(sys.argv[1]); assert z.testzip() is None; "
      "[print(i.filename, base64.b64encode(z.read(i)).decode()) for i in z.infolist()]\" '{}'",
      path.string());
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run python3");
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
  if (::pclose(pipe) != 0) throw std::runtime_error("python3 could not read " + path.string());
  std::istringstream lines(text);
  std::string name, b64;
  while (lines >> name >> b64) {
    // Base64 decoding, enough for the test.
    static const std::string chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string bytes;
    int bits = 0, value = 0;
    for (char c : b64) {
      if (c == '=') break;
      value = (value << 6) | static_cast<int>(chars.find(c));
      bits += 6;
      if (bits >= 8) {
        bits -= 8;
        bytes += static_cast<char>((value >> bits) & 0xFF);
      }
    }
    out[name] = bytes;
  }
  return out;
}

std::map<std::string, std::string> ini_of(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 3);
  }
  return out;
}

TEST(GreyscaleStack, LayerPngsAreTheGreyImagesWithTheirPixelSize) {
  const Scene scene = bars_scene("sl1s");
  const Slicer slicer(scene, {});
  const JobParams p = resin_params("stack", {"greyscale"});
  run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  for (int layer : {0, L.num_layers - 1}) {
    const fs::path file = p.output_dir / fmt::format("greyscale/slice_{}.png", layer_number(layer, L.num_layers));
    const std::string bytes = test::read_bytes(file);
    EXPECT_EQ(static_cast<unsigned char>(bytes[24]), 8u);  // bit depth
    EXPECT_EQ(static_cast<unsigned char>(bytes[25]), 0u);  // colour type 0: greyscale
    // pHYs: 20000 pixels per metre (0.05 mm) both ways, unit metre.
    const auto at = bytes.find("pHYs");
    ASSERT_NE(at, std::string::npos);
    EXPECT_EQ(bytes.substr(at + 4, 9), std::string("\x00\x00\x4e\x20\x00\x00\x4e\x20\x01", 9));
    const RgbaImage im = read_png_rgba(file);
    const GreyImage grey = slicer.slice_layer(layer).grey;
    ASSERT_EQ(im.width_px, grey.width_px());
    ASSERT_EQ(im.height_px, grey.height_px());
    for (std::size_t i = 0; i < grey.values().size(); ++i) ASSERT_EQ(im.rgba[4 * i], grey.values()[i]) << i;
  }
  EXPECT_TRUE(verify_output(p.output_dir).ok());
  fs::remove_all(p.output_dir);
}

TEST(Sl1Archive, LayersLieOnTheDisplayTurnedAndMirroredAsTheProfileSays) {
  const Scene scene = bars_scene("sl1s");
  const Slicer slicer(scene, {});
  const JobParams p = resin_params("sl1s", {"sl1s", "greyscale"});  // verify wants files per layer
  run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  EXPECT_EQ(L.num_layers, 20);            // 1 mm in 0.05 mm layers from the platform
  EXPECT_EQ((2560 - L.width_px) % 2, 0);  // the display's parity
  EXPECT_EQ((1620 - L.height_px) % 2, 0);
  const auto members = archive_members(p.output_dir / "sl1s/slice.sl1s");
  std::vector<std::string> names;
  for (const auto& [name, bytes] : members) names.push_back(name);
  std::vector<std::string> expected = {"config.ini", "prusaslicer.ini", "thumbnail/thumbnail400x400.png",
                                       "thumbnail/thumbnail800x480.png"};
  for (int i = 0; i < 20; ++i) expected.push_back(fmt::format("slice{:05d}.png", i));
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(names, expected);

  // Portrait and mirrored along x (the SL1S profile): the PNG is 1620 wide and 2560 tall; the
  // bed's y runs along its width, the bed's x up its height from the bottom row.
  const int ox = (2560 - L.width_px) / 2, oy = (1620 - L.height_px) / 2;
  for (int layer : {0, 10, 19}) {
    const std::string& png = members.at(fmt::format("slice{:05d}.png", layer));
    const RgbaImage im = decode_png_rgba(png, "layer");
    ASSERT_EQ(im.width_px, 1620);
    ASSERT_EQ(im.height_px, 2560);
    const GreyImage grey = slicer.slice_layer(layer).grey;
    std::int64_t exposed = 0;
    for (int row = 0; row < grey.height_px(); ++row)
      for (int col = 0; col < grey.width_px(); ++col) {
        const int X = ox + col, Y = oy + (grey.height_px() - 1 - row);
        const int a = Y, b = 2560 - 1 - X;
        ASSERT_EQ(im.rgba[4 * (static_cast<std::size_t>(b) * 1620 + static_cast<std::size_t>(a))], grey.at(col, row))
            << "layer " << layer << " pixel " << col << ", " << row;
        exposed += grey.at(col, row) > 0;
      }
    std::int64_t exposed_png = 0;
    for (std::size_t i = 0; i < im.rgba.size(); i += 4) exposed_png += im.rgba[i] > 0;
    EXPECT_EQ(exposed_png, exposed);  // nothing else on the display
  }
  // The block (small x, larger y) lies to the right of the bar's end, at the bottom of the
  // image: x grows upwards, y to the right.
  const RgbaImage mid = decode_png_rgba(members.at("slice00010.png"), "layer");
  auto at = [&](double x_mm, double y_mm) {
    const double cx = 0.5 * (20 + 0), cy = 0.5 * (7 + 0);  // the model's centre sits on the display's
    const int X = static_cast<int>(std::floor((64.0 + (x_mm - cx)) / 0.05));
    const int Y = static_cast<int>(std::floor((40.5 + (y_mm - cy)) / 0.05));
    return mid.rgba[4 * (static_cast<std::size_t>(2559 - X) * 1620 + static_cast<std::size_t>(Y))];
  };
  EXPECT_GT(at(1, 6), 0);          // in the block
  EXPECT_GT(at(19, 1), 0);         // in the bar's far end
  EXPECT_EQ(at(19, 6), 0);         // beside the bar's far end: nothing
  EXPECT_GT(at(19, 1), at(1, 1));  // the bar's grey grows with x (stiff = u)

  const auto config = ini_of(members.at("config.ini"));
  EXPECT_EQ(config.at("jobDir"), "slice");
  EXPECT_EQ(config.at("printerModel"), "SL1S");
  EXPECT_EQ(config.at("layerHeight"), "0.05");
  EXPECT_EQ(config.at("expTime"), "2");
  EXPECT_EQ(config.at("expTimeFirst"), "25");
  EXPECT_EQ(std::stoi(config.at("numFast")) + std::stoi(config.at("numSlow")), 20);
  EXPECT_EQ(config.at("fileCreationTimestamp"), "1980-01-01 at 00:00:00 UTC");
  // The resin the profile's exposures are for, not the scene's materials (grey levels of it).
  EXPECT_EQ(config.at("materialName"), "Prusa Orange Tough @0.05 SL1S");
  EXPECT_EQ(config.at("printProfile"), "0.05 mm greyscale (trivox)");
  EXPECT_EQ(config.size(), 19u);
  const auto settings = ini_of(members.at("prusaslicer.ini"));
  EXPECT_EQ(settings.at("display_pixels_x"), "2560");
  EXPECT_EQ(settings.at("display_pixels_y"), "1620");
  EXPECT_EQ(settings.at("display_width"), "128");
  EXPECT_EQ(settings.at("display_height"), "81");
  EXPECT_EQ(settings.at("display_orientation"), "portrait");
  EXPECT_EQ(settings.at("display_mirror_x"), "1");
  EXPECT_EQ(settings.at("display_mirror_y"), "0");
  EXPECT_EQ(settings.at("printer_technology"), "SLA");
  // The thumbnails show the part (its exposed pixels' box), centred with a margin of a
  // twentieth: the bars' box is 20 x 7 mm, wider than either thumbnail's shape.
  for (const char* thumb : {"thumbnail/thumbnail400x400.png", "thumbnail/thumbnail800x480.png"}) {
    const RgbaImage t = decode_png_rgba(members.at(thumb), thumb);
    EXPECT_EQ(fmt::format("thumbnail/thumbnail{}x{}.png", t.width_px, t.height_px), thumb);
    int x_lo = t.width_px, x_hi = -1, y_lo = t.height_px, y_hi = -1;
    for (int y = 0; y < t.height_px; ++y)
      for (int x = 0; x < t.width_px; ++x)
        if (t.rgba[4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width_px) +
                        static_cast<std::size_t>(x)) +
                   3] != 0)
          x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x), y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
    ASSERT_GE(x_hi, 0) << thumb;
    EXPECT_LE(std::abs(x_lo - (t.width_px - 1 - x_hi)), 1) << thumb;   // as much room left as right
    EXPECT_LE(std::abs(y_lo - (t.height_px - 1 - y_hi)), 1) << thumb;  // above as below
    EXPECT_NEAR(x_hi - x_lo + 1, 0.9 * t.width_px, 2) << thumb;        // the width fills all but the margin
    EXPECT_NEAR(static_cast<double>(y_hi - y_lo + 1) / (x_hi - x_lo + 1), 7.0 / 20.0, 0.02) << thumb;
  }
  const VerifyReport report = verify_output(p.output_dir);
  EXPECT_TRUE(report.ok()) << fmt::format("{}", fmt::join(report.problems, "\n"));
  fs::remove_all(p.output_dir);
}

// config.ini names the resin the exposures are for: the greyscale block's "resin", else the
// profile's default resin while the exposures are the profile's, else "unnamed resin".
TEST(Sl1Archive, ConfigNamesTheResinOfItsExposures) {
  const std::pair<std::string, std::string> cases[] = {
      {R"(, "resin": "Tough Grey @0.05", "exposure_s": 3)", "Tough Grey @0.05"},
      {R"(, "exposure_s": 3)", "unnamed resin"},
      {"", "Prusa Orange Tough @0.05"}};
  for (const auto& [keys, resin] : cases) {
    SCOPED_TRACE(keys);
    const Scene scene = bars_scene("sl1", keys);  // the slicer keeps a reference
    const Slicer slicer(scene, {});
    const JobParams p = resin_params("resin", {"sl1"});
    run_slice_job(slicer, p);
    const auto config = ini_of(archive_members(p.output_dir / "sl1/slice.sl1").at("config.ini"));
    EXPECT_EQ(config.at("materialName"), resin);
    EXPECT_EQ(config.at("expTime"), keys.find("exposure_s") != std::string::npos ? "3" : "7.5");
    fs::remove_all(p.output_dir);
  }
  EXPECT_THROW(bars_scene("sl1", R"(, "resin": "two
lines")"),
               InputError);
  EXPECT_THROW(bars_scene("sl1", R"(, "resin": "")"), InputError);
  EXPECT_THROW(bars_scene("sl1", ", \"resin\": \"" + std::string(101, 'r') + "\""), InputError);
}

TEST(Sl1Archive, SameBytesForAnyThreadCountAndAfterResume) {
  const Scene scene = bars_scene("sl1s");
  const Slicer slicer(scene, {});
  const JobParams a = resin_params("once", {"sl1s", "greyscale"}, 1);
  run_slice_job(slicer, a);
  const JobParams b = resin_params("resumed", {"sl1s", "greyscale"}, 3);
  EXPECT_TRUE(test::slice_until_stopped(slicer, b, 4).interrupted);
  EXPECT_FALSE(fs::exists(b.output_dir / "sl1s/slice.sl1s"));
  test::slice_resumed(slicer, b);
  const auto first = test::folder_bytes(a.output_dir), second = test::folder_bytes(b.output_dir);
  EXPECT_EQ(first.size(), second.size());
  for (const auto& [name, bytes] : first) {
    if (name.rfind("stats", 0) == 0) continue;  // timings
    ASSERT_TRUE(second.count(name)) << name;
    EXPECT_EQ(bytes, second.at(name)) << name;
  }
  EXPECT_TRUE(first.count("sl1s/slice.sl1s"));
  fs::remove_all(a.output_dir);
  fs::remove_all(b.output_dir);
}

TEST(Sl1Archive, RefusesPrintersWithoutItsDisplayAndModelsTooLargeForIt) {
  const Scene j750 = bars_scene("j750-hm");
  const Slicer slicer(j750, {});
  const JobParams p = resin_params("nodisplay", {"sl1s"});
  try {
    run_slice_job(slicer, p);
    ADD_FAILURE() << "an sl1s archive for a J750";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("display"), std::string::npos) << e.what();
  }
  const Scene sl1 = bars_scene("sl1");
  const Slicer sl1_slicer(sl1, {});
  try {
    run_slice_job(sl1_slicer, resin_params("wrongmodel", {"sl1s"}));
    ADD_FAILURE() << "an sl1s archive for an SL1";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--format sl1"), std::string::npos) << e.what();
  }
  fs::remove_all(p.output_dir);
  fs::remove_all(resin_params("wrongmodel", {}).output_dir);
}

}  // namespace
}  // namespace trivox
