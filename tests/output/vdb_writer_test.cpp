// The "vdb" stack output, read back with OpenVDB's reader: one float grid per material named
// after it, whose active voxels are exactly the pixels of that material in the Voxel Print
// layer images (decoded independently, the reference), placed in model space by the layout;
// the file is identical for 1 and 3 threads and after a stop and resume.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/detail/vdb_stack.h"
#include "trivox/output/layer_writer.h"
#include "trivox/output/png_io.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

// Off the origin, so that a wrong translation shows.
Scene vdb_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({2, -1, 0.5}, {5, 0.5, 0.65}))}, 2);
  s.source = "vdb-scene";
  return s;
}

JobParams vdb_params(const std::string& name, int threads) {
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-vdb-test-{}-{}", ::getpid(), name);
  fs::remove_all(p.output_dir);
  p.threads = threads;
  p.formats = {"voxelprint", "vdb"};
  p.manifest_interval_seconds = 0;
  return p;
}

TEST(VdbWriter, GridsHoldTheLayerImagesInModelSpace) {
  const Scene scene = vdb_scene();
  const Slicer slicer(scene, {});
  JobParams p = vdb_params("grids", 3);
  p.min_layers = slicer.layout().num_layers + 2;  // two empty padding layers on top
  run_slice_job(slicer, p);
  const SliceLayout& L = slicer.layout();
  const int total = *p.min_layers;

  // The reference: every material pixel of every layer PNG, as (column, rows from the bottom,
  // layer), per material.
  std::vector<std::array<std::uint8_t, 4>> palette = {job_background(scene, p)};
  for (const MaterialDef& m : scene.materials) palette.push_back(m.rgba);
  std::vector<std::vector<std::array<int, 3>>> expected(scene.materials.size());
  for (int k = 0; k < total; ++k) {
    const RgbaImage im = read_png_rgba(p.output_dir / fmt::format("slice_{}.png", layer_number(k, total)));
    ASSERT_EQ(im.width_px, L.width_px);
    ASSERT_EQ(im.height_px, L.height_px);
    for (int row = 0; row < im.height_px; ++row)
      for (int col = 0; col < im.width_px; ++col) {
        const auto* px = im.rgba.data() + 4 * (static_cast<std::size_t>(row) * im.width_px + col);
        for (std::size_t l = 1; l < palette.size(); ++l)
          if (std::equal(palette[l].begin(), palette[l].end(), px))
            expected[l - 1].push_back({col, L.height_px - 1 - row, k});
      }
  }

  const std::vector<VdbGridSummary> grids = read_vdb_stack(p.output_dir / "vdb/stack.vdb");
  ASSERT_EQ(grids.size(), scene.materials.size());
  for (std::size_t j = 0; j < grids.size(); ++j) {
    const VdbGridSummary& g = grids[j];
    EXPECT_EQ(g.name, scene.materials[j].name);
    EXPECT_EQ(g.value_type, "float");
    EXPECT_EQ(g.grid_class, "fog volume");
    EXPECT_NEAR(g.voxel_size_mm[0], L.pitch_x_mm, 1e-12);
    EXPECT_NEAR(g.voxel_size_mm[1], L.pitch_y_mm, 1e-12);
    EXPECT_NEAR(g.voxel_size_mm[2], L.layer_mm, 1e-12);
    // Index (0, 0, 0) is the centre of the bottom-left pixel of layer 0.
    EXPECT_NEAR(g.index_origin_mm[0], L.x_of_col(0), 1e-9);
    EXPECT_NEAR(g.index_origin_mm[1], L.y_of_row(L.height_px - 1), 1e-9);
    EXPECT_NEAR(g.index_origin_mm[2], L.z_of_layer(0), 1e-9);
    std::sort(expected[j].begin(), expected[j].end());
    EXPECT_FALSE(expected[j].empty()) << "material " << j << " never appears: the test would prove little";
    EXPECT_EQ(g.active, expected[j]) << "grid " << g.name;
    EXPECT_EQ(g.values_not_one, 0);
  }
  EXPECT_TRUE(verify_output(p.output_dir).ok());
  EXPECT_FALSE(fs::exists(p.output_dir / "vdb/stack.vdb.spool"));
  fs::remove_all(p.output_dir);
}

TEST(VdbWriter, IdenticalForOneAndThreeThreadsAndAfterResume) {
  const Scene scene = vdb_scene();
  const Slicer slicer(scene, {});
  const JobParams a = vdb_params("t1", 1);
  run_slice_job(slicer, a);
  const JobParams b = vdb_params("t3", 3);
  EXPECT_TRUE(test::slice_until_stopped(slicer, b, 4).interrupted);
  EXPECT_FALSE(fs::exists(b.output_dir / "vdb/stack.vdb"));
  test::slice_resumed(slicer, b);
  const std::string bytes = read_bytes(a.output_dir / "vdb/stack.vdb");
  ASSERT_GT(bytes.size(), 64u);
  EXPECT_EQ(bytes, read_bytes(b.output_dir / "vdb/stack.vdb"));
  EXPECT_EQ(read_bytes(a.output_dir / "manifest.json"), read_bytes(b.output_dir / "manifest.json"));
  // The random file UUID OpenVDB writes has been replaced by one derived from the content.
  EXPECT_NE(bytes.substr(21, 36), "00000000-0000-0000-0000-000000000000");
  EXPECT_EQ(bytes[21 + 8], '-');
  // A damaged file is caught by verify and by the reader.
  std::ofstream(b.output_dir / "vdb/stack.vdb", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_FALSE(verify_output(b.output_dir).ok());
  EXPECT_THROW(read_vdb_stack(b.output_dir / "vdb/stack.vdb"), Error);
  fs::remove_all(a.output_dir);
  fs::remove_all(b.output_dir);
}

TEST(VdbWriter, AShardKeepsItsLayersForTheGridsOfTheMergedJob) {
  const Scene scene = vdb_scene();
  const Slicer slicer(scene, {});
  JobParams p = vdb_params("shard", 1);
  p.shard_index = 1;
  p.shard_count = 2;
  run_slice_job(slicer, p);  // the merged job's resume writes them (tests/job/stack_parts_test.cpp)
  EXPECT_FALSE(fs::exists(p.output_dir / "vdb"));
  EXPECT_TRUE(fs::is_directory(p.output_dir / "stack_parts"));
  fs::remove_all(p.output_dir);
}

}  // namespace
}  // namespace trivox
