// The "gcvf" package as the public GCVF tools read it, and the choices where the public
// writers differ (docs/FORMATS.md, "GrabCAD Voxel Print package"):
//   - read back the way jackcrane/voxelprint-preview's parseGCVF.js and App.jsx do (every zip
//     member by its base name; each field the text of the first element of that tag; the
//     slices `ImageFilePrefix + i + ".png"` for i from StartIndex, NumberOfSlices of them; a
//     pixel's colour looked up among the materials' RGBA and the background), the package
//     gives the job's stack: every slice's labels, and every material's voxel count;
//   - the background is black unless a material is, the images and the RGBA fields opaque,
//     materials named by their Stratasys codes (or as the scene names them), those without a
//     voxel left out (or listed), and the extra members written when asked for.
// The reader is an independent one: Python's zipfile, xml.etree and zlib.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "support/test_support.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job.h"
#include "trivox/material/detail/constant_material.h"
#include "trivox/output/png_io.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// parseGCVF.js and the slice lookup of App.jsx, in Python. Prints, per slice, the SHA-256 of
// its labels (one byte per pixel, row-major: 0 for the background, 1 + the material's
// position in the MaterialList), the fields, the material names and voxel counts, and the
// members.
nlohmann::json read_like_the_viewer(const fs::path& archive) {
  static const char* script = R"PY(
import hashlib, json, struct, sys, zipfile, zlib
import xml.etree.ElementTree as ET
z = zipfile.ZipFile(sys.argv[1])
files = {}
for info in z.infolist():
    if not info.is_dir():
        files[info.filename.split("/")[-1]] = z.read(info)     # extractZip.js: base names
root = ET.fromstring(files["ConfigFile.xml"])
def get(tag):                                                 # querySelector(tag).textContent.trim()
    for e in root.iter(tag):
        return (e.text or "").strip()
    return None
mats = [{"name": m.find("Name").text, "rgba": [int(n) for n in m.find("RGBA").text.split(" ")],
         "voxelCount": int(m.find("VoxelCount").text or 0)} for m in root.iter("Material")]
fields = {k: get(k) for k in ["Version", "XDpi", "YDpi", "SliceThicknessNanoMeter", "SliceWidth", "SliceHeight",
                              "StartIndex", "NumberOfSlices", "ImageFilePrefix", "BackGroundMaterialRGBA"]}
start, count = int(fields["StartIndex"]), int(fields["NumberOfSlices"])
prefix = fields["ImageFilePrefix"] or "layer_"
colour_to_label = {tuple(int(n) for n in fields["BackGroundMaterialRGBA"].split(" ")): 0}
for i, m in enumerate(mats):
    colour_to_label[tuple(m["rgba"])] = i + 1
def rgba_rows(data):
    pos, idat = 8, b""
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", data[pos + 8:pos + 18])
        if kind == b"IDAT":
            idat += data[pos + 8:pos + 8 + n]
        pos += 12 + n
    assert depth == 8 and colour == 6, (depth, colour)
    raw, stride, prev, rows = zlib.decompress(idat), w * 4, bytearray(w * 4), []
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 4] if i >= 4 else 0
            b, c = prev[i], (prev[i - 4] if i >= 4 else 0)
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return w, h, rows
slices, counts, alphas = [], [0] * (len(mats) + 1), set()
for i in range(start, start + count):
    name = f"{prefix}{i}.png"
    if name not in files:                                     # App.jsx's second lookup: the number after the prefix
        name = next(k for k in files if k.endswith(".png") and int(k.replace(prefix, "").replace(".png", "")) == i)
    w, h, rows = rgba_rows(files[name])
    labels = bytearray()
    for row in rows:
        for x in range(w):
            px = tuple(row[4 * x:4 * x + 4])
            alphas.add(px[3])
            labels.append(colour_to_label[px])               # KeyError: a colour the config does not name
    for l in labels:
        counts[l] += 1
    slices.append(hashlib.sha256(bytes(labels)).hexdigest())
print(json.dumps({"fields": fields, "materials": mats, "slices": slices, "counts": counts,
                  "alphas": sorted(alphas), "members": [i.filename for i in z.infolist()]}))
)PY";
  const fs::path script_path = fs::temp_directory_path() / fmt::format("trivox-gcvf-viewer-{}.py", ::getpid());
  std::ofstream(script_path) << script;
  const std::string command = fmt::format("python3 '{}' '{}'", script_path.string(), archive.string());
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run python3");
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = ::pclose(pipe);
  fs::remove(script_path);
  if (status != 0) throw std::runtime_error("the viewer's reading failed for " + archive.string() + ": " + out);
  return nlohmann::json::parse(out);
}

// One member of a zip archive, read by Python's zipfile.
std::string zip_member(const fs::path& archive, const std::string& member) {
  const std::string cmd = fmt::format(
      "python3 -c \"import sys,zipfile; sys.stdout.buffer.write(zipfile.ZipFile(sys.argv[1]).read(sys.argv[2]))\" "
      "'{}' '{}'",
      archive.string(), member);
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot run python3");
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  if (::pclose(pipe) != 0) throw std::runtime_error("no member " + member + " in " + archive.string());
  return out;
}

JobParams package_params(const std::string& name) {
  JobParams p = test::job_in_temp_folder("trivox-gcvf-package", name, {"gcvf"});
  p.min_layers = 0;
  return p;
}

// Three VeroVivid materials graded along x, the third (black) used nowhere, and a clear one
// with alpha 60.
Scene vivid_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.1}))}, 2);
  s.source = "gcvf-package-scene";
  s.materials = {{"VeroCyan-V", {0, 147, 221, 255}, "VeroCyan-V"},
                 {"clear", {235, 240, 245, 60}, ""},
                 {"VeroBlack", {0, 0, 0, 255}, "VeroBlack"}};
  for (Cell& c : s.cells) {
    // m0 rising along u, m1 the rest; the scene's third material is never used.
    struct ThreeFromTwo final : MaterialFunction {
      std::shared_ptr<const MaterialFunction> two;
      explicit ThreeFromTwo(std::shared_ptr<const MaterialFunction> t) : MaterialFunction(3), two(std::move(t)) {}
      std::string_view kind() const noexcept override { return "three_from_two"; }
      void evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz, std::span<float> f) const override {
        std::vector<float> g(2 * uvw.size());
        two->evaluate_row(uvw, xyz, g);
        for (std::size_t k = 0; k < uvw.size(); ++k) {
          f[3 * k] = g[2 * k];
          f[3 * k + 1] = g[2 * k + 1];
          f[3 * k + 2] = 0;
        }
      }
    };
    c.material = std::make_shared<ThreeFromTwo>(c.material);
  }
  return s;
}

// The labels the package should hold, in its MaterialList's numbering.
std::string expected_slice_sha(const LabelImage& labels, const std::vector<int>& list_position) {
  std::string bytes(labels.values().size(), '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const std::uint8_t l = labels.values()[i];
    bytes[i] = static_cast<char>(l == 0 ? 0 : list_position[l - 1] + 1);
  }
  return sha256_hex(bytes);
}

TEST(GcvfPackage, ReadLikeThePublicViewerItIsTheJobsStack) {
  const Scene scene = vivid_scene();
  const Slicer slicer(scene, {});
  const JobParams p = package_params("viewer");
  run_slice_job(slicer, p);
  const nlohmann::json v = read_like_the_viewer(p.output_dir / "gcvf/stack.gcvf");
  const SliceLayout& L = slicer.layout();

  const auto& f = v["fields"];
  EXPECT_EQ(f["Version"], "2");
  EXPECT_EQ(f["XDpi"], "600");
  EXPECT_EQ(f["YDpi"], "300");
  EXPECT_EQ(f["SliceThicknessNanoMeter"], "14000");
  EXPECT_EQ(f["SliceWidth"], std::to_string(L.width_px));
  EXPECT_EQ(f["SliceHeight"], std::to_string(L.height_px));
  EXPECT_EQ(f["StartIndex"], "0");
  EXPECT_EQ(f["NumberOfSlices"], std::to_string(L.num_layers));
  EXPECT_EQ(f["ImageFilePrefix"], "slice_");
  // A black material: the background is the next free colour, white.
  EXPECT_EQ(f["BackGroundMaterialRGBA"], "255 255 255 255");
  EXPECT_EQ(v["alphas"], nlohmann::json::array({255}));  // every pixel opaque

  // The unused black material is left out; the others named by code where one is known.
  const auto& mats = v["materials"];
  ASSERT_EQ(mats.size(), 2u);
  EXPECT_EQ(mats[0]["name"], "VeroCY-V");
  EXPECT_EQ(mats[0]["rgba"], nlohmann::json::array({0, 147, 221, 255}));
  EXPECT_EQ(mats[1]["name"], "clear");
  EXPECT_EQ(mats[1]["rgba"], nlohmann::json::array({235, 240, 245, 255}));

  // Every slice, label for label, and the voxel counts.
  std::vector<std::int64_t> counts(3, 0);
  ASSERT_EQ(v["slices"].size(), static_cast<std::size_t>(L.num_layers));
  for (int layer = 0; layer < L.num_layers; ++layer) {
    const LabelImage labels = slicer.slice_layer(layer).labels;
    EXPECT_EQ(v["slices"][static_cast<std::size_t>(layer)], expected_slice_sha(labels, {0, 1, -1}))
        << "slice " << layer;
    for (std::uint8_t l : labels.values())
      if (l > 0) ++counts[l - 1];
  }
  ASSERT_EQ(counts[2], 0);
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 0);
  EXPECT_EQ(mats[0]["voxelCount"].get<std::int64_t>(), counts[0]);
  EXPECT_EQ(mats[1]["voxelCount"].get<std::int64_t>(), counts[1]);
  EXPECT_EQ(v["counts"][1].get<std::int64_t>(), counts[0]);
  EXPECT_EQ(v["counts"][2].get<std::int64_t>(), counts[1]);
  EXPECT_EQ(v["members"].back(), "ConfigFile.xml");

  // materials.csv keeps the scene's names, in the images' (opaque) colours.
  const std::string sheet = test::read_bytes(p.output_dir / "materials.csv");
  EXPECT_NE(sheet.find("0,background,,#FFFFFFFF,255,255,255,255\n"), std::string::npos) << sheet;
  EXPECT_NE(sheet.find("1,VeroCyan-V,VeroCyan-V,#0093DDFF,"), std::string::npos) << sheet;
  EXPECT_NE(sheet.find("2,clear,,#EBF0F5FF,235,240,245,255\n"), std::string::npos) << sheet;
  fs::remove_all(p.output_dir);
}

TEST(GcvfPackage, SceneNamesEveryMaterialListedAndExtraMembersOnRequest) {
  const Scene scene = vivid_scene();
  const Slicer slicer(scene, {});
  JobParams p = package_params("options");
  p.gcvf.material_codes = false;
  p.gcvf.omit_unused = false;
  p.gcvf.mesh_stl = true;
  p.gcvf.bounding_box = true;
  run_slice_job(slicer, p);
  const nlohmann::json v = read_like_the_viewer(p.output_dir / "gcvf/stack.gcvf");
  const auto& mats = v["materials"];
  ASSERT_EQ(mats.size(), 3u);
  EXPECT_EQ(mats[0]["name"], "VeroCyan-V");
  EXPECT_EQ(mats[2]["name"], "VeroBlack");
  EXPECT_EQ(mats[2]["voxelCount"], 0);
  const SliceLayout& L = slicer.layout();
  for (int layer : {0, L.num_layers / 2})
    EXPECT_EQ(v["slices"][static_cast<std::size_t>(layer)],
              expected_slice_sha(slicer.slice_layer(layer).labels, {0, 1, 2}));
  const auto& members = v["members"];
  ASSERT_GE(members.size(), 3u);
  EXPECT_EQ(members[members.size() - 3], "ConfigFile.xml");
  EXPECT_EQ(members[members.size() - 2], "model.stl");
  EXPECT_EQ(members[members.size() - 1], "bounding_box.txt");

  // The members as written: a binary STL of the box's six faces (32 x 32 x 2 triangles
  // each) facing outwards, and the box the images cover.
  const std::string stl = zip_member(p.output_dir / "gcvf/stack.gcvf", "model.stl");
  const std::string bbox = zip_member(p.output_dir / "gcvf/stack.gcvf", "bounding_box.txt");
  EXPECT_EQ(bbox, fmt::format("# trivox: the box the layer images cover, mm in model space: x_min y_min z_min x_max "
                              "y_max z_max\n{} {} {} {} {} {}\n",
                              L.x0_mm, L.y_top_mm - L.height_px * L.pitch_y_mm, L.z0_mm,
                              L.x0_mm + L.width_px * L.pitch_x_mm, L.y_top_mm, L.z0_mm + L.num_layers * L.layer_mm));
  ASSERT_GE(stl.size(), 84u);
  std::uint32_t triangles = 0;
  std::memcpy(&triangles, stl.data() + 80, 4);
  EXPECT_EQ(triangles, 6u * 32 * 32 * 2);
  EXPECT_EQ(stl.size(), 84u + 50u * triangles);
  for (std::uint32_t t = 0; t < triangles; t += 97) {
    float v9[12];
    std::memcpy(v9, stl.data() + 84 + 50 * t, sizeof v9);
    for (int k = 1; k < 4; ++k) {
      EXPECT_GE(v9[3 * k], -1e-5f);
      EXPECT_LE(v9[3 * k], 3 + 1e-5f);
      EXPECT_GE(v9[3 * k + 2], -1e-5f);
      EXPECT_LE(v9[3 * k + 2], 0.1f + 1e-5f);
    }
    // Facing outwards: the normal points away from the box's centre.
    const float cx = (v9[3] + v9[6] + v9[9]) / 3 - 1.5f, cy = (v9[4] + v9[7] + v9[10]) / 3 - 0.75f,
                cz = (v9[5] + v9[8] + v9[11]) / 3 - 0.05f;
    EXPECT_GT(v9[0] * cx + v9[1] * cy + v9[2] * cz, 0.0f) << "triangle " << t;
  }
  fs::remove_all(p.output_dir);
}

TEST(GcvfPackage, BackgroundIsBlackUnlessAMaterialIsThenTheFirstFreeColour) {
  Scene scene = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {1, 1, 1}), 0, 2)}, 2);
  JobParams p;
  scene.materials[0].rgba = {10, 20, 30, 255};
  scene.materials[1].rgba = {40, 50, 60, 128};
  EXPECT_EQ(job_background(scene, p), (std::array<std::uint8_t, 4>{0, 0, 0, 255}));
  scene.materials[1].rgba = {0, 0, 0, 17};  // black whatever its alpha: the images are opaque
  EXPECT_EQ(job_background(scene, p), (std::array<std::uint8_t, 4>{255, 255, 255, 255}));
  scene.materials[0].rgba = {255, 255, 255, 255};
  EXPECT_EQ(job_background(scene, p), (std::array<std::uint8_t, 4>{1, 1, 1, 255}));
  p.background_rgba = std::array<std::uint8_t, 4>{9, 9, 9, 255};
  EXPECT_EQ(job_background(scene, p), (std::array<std::uint8_t, 4>{9, 9, 9, 255}));
}

TEST(GcvfPackage, MaterialsThatDifferOnlyInAlphaAreRefused) {
  Scene scene = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {1, 1, 0.1}), 0, 2)}, 2);
  scene.materials[1].rgba = scene.materials[0].rgba;
  scene.materials[1].rgba[3] = 100;
  const Slicer slicer(scene, {});
  JobParams p = package_params("alpha");
  p.formats = {"voxelprint"};
  try {
    run_slice_job(slicer, p);
    ADD_FAILURE() << "two materials of one opaque colour were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("opaque"), std::string::npos) << e.what();
  }
  p.background_rgba = std::array<std::uint8_t, 4>{0, 0, 0, 128};
  EXPECT_THROW(check_job_settings(slicer, p), Error);
  fs::remove_all(p.output_dir);
}

}  // namespace
}  // namespace trivox
