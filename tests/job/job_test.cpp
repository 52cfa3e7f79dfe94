// Whole jobs: files, formats, padding and determinism across thread counts.
#include "trivox/job/job.h"

#include <fstream>
#include <iterator>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

// A job with two materials: a gradient box and a ring cell on top of it.
Scene two_material_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {12, 6, 0.2}))}, 2);
  s.cells.push_back(test::constant_cell(
      Volume(test::annulus_sector(1, 4, 0.2).spline().transformed([](std::span<double> q) { q[0] += 6; })), 0, 2,
      "ring"));
  return s;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-job-test-{}", name);
  fs::remove_all(dir);
  return dir;
}

TEST(SliceJob, OutputIsIdenticalForOneAndTwoThreads) {
  const Scene scene = two_material_scene();
  const Slicer slicer(scene, {});
  std::vector<fs::path> dirs;
  std::vector<std::vector<std::string>> file_lists;
  for (int threads : {1, 2, 2}) {
    JobParams p;
    p.output_dir = fresh_dir(fmt::format("threads{}-{}", threads, dirs.size()));
    p.threads = threads;
    p.formats = {"voxelprint", "bitmaps"};
    const JobStats st = run_slice_job(slicer, p);
    dirs.push_back(p.output_dir);
    file_lists.push_back(st.files);
  }
  ASSERT_FALSE(file_lists[0].empty());
  EXPECT_EQ(file_lists[0], file_lists[1]);
  EXPECT_EQ(file_lists[0], file_lists[2]);
  for (const std::string& f : file_lists[0]) {
    const std::string a = read_bytes(dirs[0] / f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, read_bytes(dirs[1] / f)) << f;
    EXPECT_EQ(a, read_bytes(dirs[2] / f)) << f;
  }
}

// Every dithering method, with layer variation and a skin: the same bytes for one and two
// threads (blue noise is seeded by voxel position, error diffusion runs within a layer).
TEST(SliceJob, EveryDitherMethodIsIndependentOfTheThreadCount) {
  const Scene scene = two_material_scene();
  for (std::string_view name : dither_method_names()) {
    SliceParams params;
    DitherParams d;
    ASSERT_TRUE(set_dither_method(name, d));
    d.skin_voxels = 1;
    params.dither = d;
    const Slicer slicer(scene, params);
    std::vector<fs::path> dirs;
    std::vector<std::vector<std::string>> file_lists;
    for (int threads : {1, 2}) {
      JobParams p;
      p.output_dir = fresh_dir(fmt::format("method-{}-threads{}", name, threads));
      p.threads = threads;
      p.min_layers = 0;
      file_lists.push_back(run_slice_job(slicer, p).files);
      dirs.push_back(p.output_dir);
    }
    ASSERT_FALSE(file_lists[0].empty());
    ASSERT_EQ(file_lists[0], file_lists[1]);
    for (const std::string& f : file_lists[0])
      EXPECT_EQ(read_bytes(dirs[0] / f), read_bytes(dirs[1] / f)) << name << ": " << f;
    EXPECT_EQ(read_bytes(dirs[0] / "materials.csv"), read_bytes(dirs[1] / "materials.csv")) << name;
    const auto stats = nlohmann::json::parse(read_bytes(dirs[0] / "stats.json"));
    EXPECT_EQ(stats["dithering"]["method"], std::string(name));
    EXPECT_EQ(stats["dithering"]["skin_voxels"], 1);
  }
}

// stats.json: the pixels each cell owns, per layer and in total, add up to the inside pixels
// (every cell has a non-empty material, so every inside pixel is owned), and match what the
// slicer reports for the layer.
// The two-material scene sliced whole into a fresh folder; its stats.json.
nlohmann::json two_material_stats(const Slicer& slicer, const std::string& folder) {
  JobParams p;
  p.output_dir = fresh_dir(folder);
  p.min_layers = 0;
  run_slice_job(slicer, p);
  return nlohmann::json::parse(read_bytes(p.output_dir / "stats.json"));
}

TEST(SliceJob, StatsListThePixelsOfEveryCell) {
  const Scene scene = two_material_scene();
  const Slicer slicer(scene, {});
  const auto stats = two_material_stats(slicer, "pixels-per-cell");
  ASSERT_EQ(stats.at("cells").size(), 2u);
  EXPECT_EQ(stats["cells"][0], "gradient");
  EXPECT_EQ(stats["cells"][1], "ring");
  std::vector<long> total(2, 0);
  int layers_with_both = 0;
  for (const auto& layer : stats.at("layers")) {
    const auto per_cell = layer.at("pixels_per_cell").get<std::vector<long>>();
    ASSERT_EQ(per_cell.size(), 2u);
    EXPECT_EQ(per_cell[0] + per_cell[1], layer.at("pixels_inside").get<long>()) << layer.at("layer");
    const LayerStats direct = slicer.slice_layer(layer.at("layer").get<int>() - 1).stats;
    EXPECT_EQ(std::vector<long>(direct.pixels_per_cell.begin(), direct.pixels_per_cell.end()), per_cell);
    total[0] += per_cell[0];
    total[1] += per_cell[1];
    layers_with_both += per_cell[0] > 0 && per_cell[1] > 0;
  }
  EXPECT_GT(layers_with_both, 0);
  EXPECT_EQ(stats.at("total").at("pixels_per_cell").get<std::vector<long>>(), total);
  EXPECT_EQ(total[0] + total[1], stats["total"].at("pixels_inside").get<long>());
}

// stats.json: how the tracer settled each candidate pixel. Every candidate is settled once,
// by a guess that hit, a Jacobian step or the slow path (a Jacobian step that cannot settle
// its pixel hands it to the slow path, so those two may count a pixel both), and every
// evaluation is counted.
TEST(SliceJob, StatsSayHowThePixelsWereSettled) {
  const Scene scene = two_material_scene();
  const Slicer slicer(scene, {});
  const auto stats = two_material_stats(slicer, "settled");
  for (const auto& s : {stats.at("total"), stats.at("layers").at(0)}) {
    const long candidates = s.at("candidates"), guesses = s.at("guesses"), misses = s.at("guess_misses"),
               steps = s.at("jacobian_steps"), slow = s.at("slow_path_pixels"), evals = s.at("newton_evals");
    EXPECT_LE(misses, guesses);
    EXPECT_LE(guesses - misses + slow, candidates);
    EXPECT_GE(guesses - misses + steps + slow, candidates);
    EXPECT_GE(evals, guesses + steps);
  }
  EXPECT_GT(stats["total"].at("guesses").get<long>(), stats["total"].at("candidates").get<long>() / 2);
}

// stats.json writes every counter of kTraceCounterFields, per layer as the slicer counted
// it and in total as the sum of the layers (LayerStats' +=).
TEST(SliceJob, StatsWriteEveryCounterPerLayerAndTheirSum) {
  const Scene scene = two_material_scene();
  const Slicer slicer(scene, {});
  const auto stats = two_material_stats(slicer, "every-counter");
  LayerStats sum;
  for (const auto& layer : stats.at("layers")) {
    const LayerStats direct = slicer.slice_layer(layer.at("layer").get<int>() - 1).stats;
    for (const TraceCounterField& f : kTraceCounterFields)
      EXPECT_EQ(layer.at(std::string(f.name)).get<std::int64_t>(), direct.*f.member) << f.name;
    sum += direct;
  }
  int nonzero = 0;
  for (const TraceCounterField& f : kTraceCounterFields) {
    EXPECT_EQ(stats.at("total").at(std::string(f.name)).get<std::int64_t>(), sum.*f.member) << f.name;
    nonzero += sum.*f.member != 0;
  }
  EXPECT_GE(nonzero, 5);  // the scene exercises most of them
  EXPECT_EQ(stats["total"].at("pixels_inside").get<std::int64_t>(), sum.pixels_inside);
}

// The scene's dithering applies unless the slice parameters give their own.
TEST(SliceJob, SceneDitheringAppliesUnlessOverridden) {
  Scene scene = two_material_scene();
  DitherParams from_scene;
  set_dither_method("stucki", from_scene);
  scene.dithering = from_scene;
  EXPECT_EQ(dither_method_name(Slicer(scene, {}).dither_params()), "stucki");
  SliceParams params;
  params.dither = DitherParams{};
  params.dither->method = DitherMethod::kBlueNoise;
  EXPECT_EQ(dither_method_name(Slicer(scene, params).dither_params()), "blue-noise");
  scene.dithering.reset();
  EXPECT_EQ(dither_method_name(Slicer(scene, {}).dither_params()), "floyd-steinberg");
}

// materials.csv: the background and every material with its colour, listed in the manifest.
TEST(SliceJob, WritesTheColourToMaterialSheet) {
  Scene scene = two_material_scene();
  scene.materials[0].name = "Vero, \"quoted\"";
  scene.materials[1].library = "VeroCyan";
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fresh_dir("sheet");
  p.min_layers = 0;
  p.background_rgba = std::array<std::uint8_t, 4>{1, 2, 3, 255};
  run_slice_job(slicer, p);
  const std::string expected =
      "label,name,library,hex,r,g,b,a\n"
      "0,background,,#010203FF,1,2,3,255\n" +
      fmt::format("1,\"Vero, \"\"quoted\"\"\",,#{:02X}{:02X}{:02X}{:02X},{},{},{},{}\n", scene.materials[0].rgba[0],
                  scene.materials[0].rgba[1], scene.materials[0].rgba[2], scene.materials[0].rgba[3],
                  scene.materials[0].rgba[0], scene.materials[0].rgba[1], scene.materials[0].rgba[2],
                  scene.materials[0].rgba[3]) +
      fmt::format("2,m1,VeroCyan,#{:02X}{:02X}{:02X}{:02X},{},{},{},{}\n", scene.materials[1].rgba[0],
                  scene.materials[1].rgba[1], scene.materials[1].rgba[2], scene.materials[1].rgba[3],
                  scene.materials[1].rgba[0], scene.materials[1].rgba[1], scene.materials[1].rgba[2],
                  scene.materials[1].rgba[3]);
  EXPECT_EQ(read_bytes(p.output_dir / "materials.csv"), expected);
  const auto manifest = nlohmann::json::parse(read_bytes(p.output_dir / "manifest.json"));
  EXPECT_NE(manifest.dump().find("materials.csv"), std::string::npos);
}

TEST(SliceJob, VoxelPrintStackIsRgbaEqualSizedColourExactAndBitmapsPartition) {
  const Scene scene = two_material_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fresh_dir("formats");
  p.formats = {"voxelprint", "bitmaps"};
  const JobStats st = run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  ASSERT_LT(L.num_layers, 30);  // 0.2 mm at 14 um: 15 layers, so the stack is padded
  EXPECT_EQ(st.padded_layers, 30 - L.num_layers);

  const std::array<std::uint8_t, 4> background = job_background(scene, p);
  EXPECT_EQ(background, (std::array<std::uint8_t, 4>{0, 0, 0, 255}));  // no material is black
  std::set<std::array<std::uint8_t, 4>> palette = {background};
  for (const MaterialDef& m : scene.materials) palette.insert(m.rgba);
  int stacks = 0;
  for (int i = 0; i < 30; ++i) {
    const std::string num = layer_number(i, 30);
    const RgbaImage img = read_png_rgba(p.output_dir / (fmt::format("slice_{}.png", num)));
    ASSERT_EQ(img.width_px, L.width_px);
    ASSERT_EQ(img.height_px, L.height_px);
    // Colour type 6 (RGBA) in the IHDR chunk: byte 25 of the file.
    EXPECT_EQ(static_cast<unsigned char>(read_bytes(p.output_dir / (fmt::format("slice_{}.png", num)))[25]), 6u);
    const RgbaImage b0 = read_png_rgba(p.output_dir / (fmt::format("bitmaps/slice_{}_m0.png", num)));
    const RgbaImage b1 = read_png_rgba(p.output_dir / (fmt::format("bitmaps/slice_{}_m1.png", num)));
    std::int64_t occupied = 0, in_bitmaps = 0;
    for (std::size_t px = 0; px < img.rgba.size() / 4; ++px) {
      const std::array<std::uint8_t, 4> c{img.rgba[4 * px], img.rgba[4 * px + 1], img.rgba[4 * px + 2],
                                          img.rgba[4 * px + 3]};
      ASSERT_TRUE(palette.count(c)) << "colour outside the palette in layer " << i;
      const bool on0 = b0.rgba[4 * px] != 0, on1 = b1.rgba[4 * px] != 0;
      EXPECT_FALSE(on0 && on1);  // at most one material per voxel
      const bool occupied_px = c != background;
      occupied += occupied_px;
      in_bitmaps += on0 || on1;
      if (occupied_px) {
        EXPECT_EQ(on0 ? scene.materials[0].rgba : scene.materials[1].rgba, c);
      }
    }
    EXPECT_EQ(occupied, in_bitmaps);  // the bitmaps partition the occupied pixels
    if (i < L.num_layers) {
      EXPECT_GT(occupied, 0);
    } else {
      EXPECT_EQ(occupied, 0);  // padding layers are empty
    }
    ++stacks;
  }
  EXPECT_EQ(stacks, 30);

  const auto stats = nlohmann::json::parse(read_bytes(p.output_dir / "stats.json"));
  EXPECT_EQ(stats["total"]["layers_sliced"], L.num_layers);
  EXPECT_EQ(stats["total"]["layers_padded"], st.padded_layers);
  EXPECT_EQ(stats["layers"].size(), static_cast<std::size_t>(L.num_layers));
  EXPECT_GT(stats["total"]["pixels_inside"].get<std::int64_t>(), 0);
}

TEST(SliceJob, RefusesMoreMaterialsThanThePrinterTakes) {
  Scene s = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {2, 2, 0.1}), 0, 4)}, 4, "j750-hs");
  const Slicer slicer(s, {});
  JobParams p;
  p.output_dir = fresh_dir("too-many");
  EXPECT_THROW(run_slice_job(slicer, p), Error);
  EXPECT_FALSE(fs::exists(p.output_dir / "slice_00001.png"));
}

TEST(SliceJob, DuplicateColoursAreRejected) {
  Scene s = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {2, 2, 0.1}), 0, 2)}, 2);
  s.materials[1].rgba = s.materials[0].rgba;
  const Slicer slicer(s, {});
  JobParams p;
  p.output_dir = fresh_dir("dup-colours");
  EXPECT_THROW(run_slice_job(slicer, p), Error);
}

}  // namespace
}  // namespace trivox
