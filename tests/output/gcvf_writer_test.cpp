// The "gcvf" stack output, opened with an independent zip reader (Python's zipfile, which
// also checks every entry's CRC): the PNG entries are byte for byte the "voxelprint" layer
// files, in layer order, and ConfigFile.xml gives the job's resolution, size, slice count and
// materials with voxel counts that match the layer images (counted from the decoded PNGs, the
// reference); the package is identical for 1 and 3 threads and after a stop and resume. The
// zip writer itself is checked the same way, ZIP64 records included.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "job/job_fixtures.h"
#include "output/zip_writer.h"
#include "slice/slice_fixtures.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

// Lists the archive with Python's zipfile: per entry its name, size, SHA-256, method and
// date; the configuration's fields parsed with xml.etree. Throws when python3 fails.
nlohmann::json inspect_zip(const fs::path& archive) {
  static const char* script = R"PY(
import hashlib, json, sys, zipfile
import xml.etree.ElementTree as ET
z = zipfile.ZipFile(sys.argv[1])
bad = z.testzip()
entries = []
config = None
for info in z.infolist():
    data = z.read(info)
    entries.append({"name": info.filename, "size": len(data), "sha256": hashlib.sha256(data).hexdigest(),
                    "method": info.compress_type, "date": list(info.date_time)})
    if info.filename == "ConfigFile.xml":
        root = ET.fromstring(data)
        config = {"root": root.tag}
        for tag in ["Version", "Resolution/XDpi", "Resolution/YDpi", "Resolution/SliceThicknessNanoMeter",
                    "SliceDimensions/SliceWidth", "SliceDimensions/SliceHeight", "SliceRange/StartIndex",
                    "SliceRange/NumberOfSlices", "ImageFilePrefix", "DataSemantics",
                    "MaterialList/BackGroundMaterialRGBA"]:
            config[tag] = root.findtext(tag)
        config["materials"] = [{"name": m.findtext("Name"), "rgba": m.findtext("RGBA"),
                                "voxels": int(m.findtext("VoxelCount"))} for m in root.findall("MaterialList/Material")]
print(json.dumps({"bad": bad, "entries": entries, "config": config}))
)PY";
  const fs::path script_path = fs::temp_directory_path() / fmt::format("trivox-gcvf-inspect-{}.py", ::getpid());
  std::ofstream(script_path) << script;
  const std::string command = fmt::format("python3 '{}' '{}'", script_path.string(), archive.string());
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run python3");
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = ::pclose(pipe);
  fs::remove(script_path);
  if (status != 0) throw std::runtime_error("python3 could not read " + archive.string() + ": " + out);
  return nlohmann::json::parse(out);
}

Scene gcvf_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.12}))}, 2);
  s.source = "gcvf-scene";
  return s;
}

JobParams gcvf_params(const std::string& name, int threads) {
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-gcvf-test-{}-{}", ::getpid(), name);
  fs::remove_all(p.output_dir);
  p.threads = threads;
  p.formats = {"voxelprint", "gcvf"};
  p.manifest_interval_seconds = 0;
  return p;
}

TEST(GcvfWriter, EntriesAreTheVoxelPrintLayersAndTheConfigDescribesTheJob) {
  const Scene scene = gcvf_scene();
  const Slicer slicer(scene, {});
  const JobParams p = gcvf_params("entries", 3);
  run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  const int total = std::max(L.num_layers, min_layers_of(p));  // padding layers included
  const nlohmann::json z = inspect_zip(p.output_dir / "gcvf/stack.gcvf");
  EXPECT_TRUE(z["bad"].is_null()) << "CRC mismatch in " << z["bad"];
  const auto& entries = z["entries"];
  ASSERT_EQ(entries.size(), static_cast<std::size_t>(total) + 1);

  // The reference voxel counts: every pixel of every decoded layer PNG, by colour.
  std::map<std::array<std::uint8_t, 4>, std::int64_t> by_colour;
  for (int k = 0; k < total; ++k) {
    const fs::path layer = p.output_dir / fmt::format("slice_{}.png", layer_number(k, total));
    EXPECT_EQ(entries[static_cast<std::size_t>(k)]["name"], fmt::format("slice_{}.png", k));
    EXPECT_EQ(entries[static_cast<std::size_t>(k)]["sha256"], sha256_file(layer).sha256) << "layer " << k + 1;
    EXPECT_EQ(entries[static_cast<std::size_t>(k)]["method"], 0);  // stored
    EXPECT_EQ(entries[static_cast<std::size_t>(k)]["date"], nlohmann::json({1980, 1, 1, 0, 0, 0}));
    const RgbaImage im = read_png_rgba(layer);
    for (std::size_t px = 0; px < im.rgba.size(); px += 4)
      ++by_colour[{im.rgba[px], im.rgba[px + 1], im.rgba[px + 2], im.rgba[px + 3]}];
  }
  EXPECT_EQ(entries.back()["name"], "ConfigFile.xml");
  const auto& c = z["config"];
  EXPECT_EQ(c["root"], "GCVF");
  EXPECT_EQ(c["Version"], "2");
  EXPECT_EQ(c["Resolution/XDpi"], fmt::format("{}", std::lround(scene.printer.x_dpi)));
  EXPECT_EQ(c["Resolution/YDpi"], fmt::format("{}", std::lround(scene.printer.y_dpi)));
  EXPECT_EQ(c["Resolution/SliceThicknessNanoMeter"], fmt::format("{}", std::llround(L.layer_mm * 1e6)));
  EXPECT_EQ(c["SliceDimensions/SliceWidth"], fmt::format("{}", L.width_px));
  EXPECT_EQ(c["SliceDimensions/SliceHeight"], fmt::format("{}", L.height_px));
  EXPECT_EQ(c["SliceRange/StartIndex"], "0");
  EXPECT_EQ(c["SliceRange/NumberOfSlices"], fmt::format("{}", total));
  EXPECT_EQ(c["ImageFilePrefix"], "slice_");
  EXPECT_EQ(c["DataSemantics"], "Materials");
  EXPECT_EQ(c["MaterialList/BackGroundMaterialRGBA"], "0 0 0 255");  // the public packages' background
  ASSERT_EQ(c["materials"].size(), scene.materials.size());
  for (std::size_t j = 0; j < scene.materials.size(); ++j) {
    const auto& m = c["materials"][j];
    const auto& rgba = scene.materials[j].rgba;
    EXPECT_EQ(m["name"], scene.materials[j].name);
    EXPECT_EQ(m["rgba"], fmt::format("{} {} {} {}", rgba[0], rgba[1], rgba[2], rgba[3]));
    EXPECT_GT(m["voxels"].get<std::int64_t>(), 0);
    EXPECT_EQ(m["voxels"].get<std::int64_t>(), by_colour[rgba]) << scene.materials[j].name;
  }
  EXPECT_TRUE(verify_output(p.output_dir).ok());
  EXPECT_FALSE(fs::exists(p.output_dir / "gcvf/stack.gcvf.spool"));
  fs::remove_all(p.output_dir);
}

TEST(GcvfWriter, IdenticalForOneAndThreeThreadsAndAfterResume) {
  const Scene scene = gcvf_scene();
  const Slicer slicer(scene, {});
  const JobParams a = gcvf_params("t1", 1);
  run_slice_job(slicer, a);
  const JobParams b = gcvf_params("t3", 3);
  EXPECT_TRUE(test::slice_until_stopped(slicer, b, 3).interrupted);
  EXPECT_FALSE(fs::exists(b.output_dir / "gcvf/stack.gcvf"));
  test::slice_resumed(slicer, b);
  const std::string bytes = read_bytes(a.output_dir / "gcvf/stack.gcvf");
  ASSERT_GT(bytes.size(), 100u);
  EXPECT_EQ(bytes, read_bytes(b.output_dir / "gcvf/stack.gcvf"));
  EXPECT_EQ(read_bytes(a.output_dir / "manifest.json"), read_bytes(b.output_dir / "manifest.json"));
  std::ofstream(b.output_dir / "gcvf/stack.gcvf", std::ios::binary) << bytes.substr(0, bytes.size() - 30);
  EXPECT_FALSE(verify_output(b.output_dir).ok());
  fs::remove_all(a.output_dir);
  fs::remove_all(b.output_dir);
}

TEST(GcvfWriter, RefusesPitchesOfFractionalDpi) {
  OutputContext ctx;
  ctx.dir = fs::temp_directory_path() / fmt::format("trivox-gcvf-test-{}-dpi", ::getpid());
  fs::create_directories(ctx.dir);
  ctx.material_names = {"m0"};
  ctx.material_rgba = {{0, 255, 255, 255}};
  ctx.pitch_x_mm = 25.4 / 600;
  ctx.pitch_y_mm = 25.4 / 300.5;
  try {
    make_layer_writer("gcvf", ctx);
    ADD_FAILURE() << "a 300.5 dpi pitch was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("whole"), std::string::npos) << e.what();
  }
  fs::remove_all(ctx.dir);
}

// The zip container alone: classic records, and ZIP64 records forced for every field.
TEST(ZipWriter, ClassicAndZip64ArchivesReadBackInOrder) {
  for (const std::uint64_t zip64_from : {std::uint64_t{0xFFFFFFFFu}, std::uint64_t{0}}) {
    const fs::path path = fs::temp_directory_path() / fmt::format("trivox-zip-test-{}-{}.zip", ::getpid(), zip64_from);
    const std::vector<std::pair<std::string, std::string>> files = {
        {"a.png", std::string("\x89PNG\r\n\x1a\n", 8) + std::string(1000, '\x07')},
        {"dir/empty.txt", ""},
        {"b.xml", "<x/>\n"}};
    {
      AtomicFile out(path);
      detail::ZipWriter zip(out.file(), path.string(), zip64_from);
      for (const auto& [name, bytes] : files) zip.add(name, bytes);
      zip.finish();
      out.commit();
    }
    const nlohmann::json z = inspect_zip(path);
    EXPECT_TRUE(z["bad"].is_null());
    ASSERT_EQ(z["entries"].size(), files.size());
    for (std::size_t i = 0; i < files.size(); ++i) {
      EXPECT_EQ(z["entries"][i]["name"], files[i].first);
      EXPECT_EQ(z["entries"][i]["size"], files[i].second.size());
      EXPECT_EQ(z["entries"][i]["sha256"], sha256_hex(files[i].second));
    }
    const std::string bytes = read_bytes(path);
    // ZIP64 end record present exactly when forced.
    EXPECT_EQ(bytes.find(std::string("PK\x06\x06", 4)) != std::string::npos, zip64_from == 0);
    fs::remove(path);
  }
}

}  // namespace
}  // namespace trivox
