// The stack outputs of a sharded job (docs/CLUSTER.md, "Stack formats"): each shard keeps its
// layers as stack parts, the merge lists them and says what is still to write, and the whole
// job's resume writes the stack outputs from them: every file, the manifest included, has the
// bytes of one run, and the parts are gone. Also: a damaged part is sliced again, an
// interrupted shard keeps its parts, and a part that does not fit the job is refused.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/output/detail/stack_parts.h"
#include "trivox/output/png_io.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

JobParams parts_params(const std::string& name, std::vector<std::string> formats) {
  return test::job_in_temp_folder("trivox-stack-parts", name, std::move(formats));
}

// A graded box and a greyscale resin scene: the stack outputs of a Stratasys job and of a
// resin job.
Scene box_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.4}))}, 2);
  s.source = "parts-box";
  return s;
}

Scene resin_scene() {
  const std::string json = R"({
    "units": "mm", "printer": "sl1s",
    "materials": [{ "name": "stiff", "rgba": [255, 128, 64] }, { "name": "soft", "rgba": [64, 128, 255] }],
    "greyscale": { "source": { "material": "stiff" }, "curve": [[0, 40], [1, 240]], "antialiasing": 2 },
    "cells": [{ "name": "wedge", "geometry": { "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
        "points": [[0,0,0],[6,0,0],[0,3,0],[6,3,0],[0,0,0.5],[4,0,0.5],[0,3,0.5],[4,3,0.5]] },
      "material": { "kind": "expression", "fractions": { "stiff": "u", "soft": "1 - u" } } }]
  })";
  return parse_scene(json, fs::temp_directory_path() / "parts-resin.json");
}

// Slices `p`'s job as `shards` shards and merges them; returns the merged manifest.
JobManifest slice_shards_and_merge(const Slicer& slicer, JobParams p, int shards) {
  p.shard_count = shards;
  for (int i = 1; i <= shards; ++i) {
    p.shard_index = i;
    run_slice_job(slicer, p);
  }
  return merge_shards(p.output_dir);
}

// Every file of `one` (stats left out) has the same bytes in `merged`, which holds nothing
// else but the shards' statistics.
void expect_same_files(const fs::path& one, const fs::path& merged) {
  const auto a = test::folder_bytes(one), b = test::folder_bytes(merged);
  EXPECT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) {
    const auto it = b.find(name);
    ASSERT_NE(it, b.end()) << name << " is missing";
    EXPECT_TRUE(it->second == bytes) << name << " differs";
  }
  for (const auto& [name, bytes] : b) EXPECT_TRUE(a.count(name)) << name << " is extra";
}

void expect_shards_make_one_run(const Scene& scene, const std::vector<std::string>& formats, const std::string& name,
                                std::vector<int> preview_layers = {}) {
  const Slicer slicer(scene, {});
  JobParams one = parts_params(name + "-one", formats), sharded = parts_params(name + "-shards", formats);
  one.preview_layers = sharded.preview_layers = preview_layers;
  run_slice_job(slicer, one);

  const JobManifest merged = slice_shards_and_merge(slicer, sharded, 3);
  EXPECT_EQ(merged.status, JobStatus::kInterrupted);
  EXPECT_NE(merged.message.find("still to be written from the layers they kept: run `trivox slice"), std::string::npos)
      << merged.message;
  EXPECT_TRUE(fs::is_directory(sharded.output_dir / "stack_parts"));
  EXPECT_FALSE(verify_output(sharded.output_dir).ok());  // not complete yet

  // The whole job's resume slices nothing: every layer comes from its parts.
  const JobStats resumed = test::slice_resumed(slicer, sharded);
  EXPECT_TRUE(resumed.layers.empty());
  EXPECT_EQ(resumed.layers_kept, merged.total_layers);
  EXPECT_FALSE(fs::exists(sharded.output_dir / "stack_parts"));
  expect_same_files(one.output_dir, sharded.output_dir);
  EXPECT_TRUE(verify_output(sharded.output_dir).ok());
  fs::remove_all(one.output_dir);
  fs::remove_all(sharded.output_dir);
}

TEST(StackParts, ShardsOfAStratasysJobMakeTheStackOutputsOfOneRun) {
  expect_shards_make_one_run(box_scene(), {"voxelprint", "gcvf", "tiff", "vdb", "preview"}, "stratasys", {2, 5});
}

TEST(StackParts, ShardsOfAGreyscaleJobMakeTheArchiveOfOneRun) {
  expect_shards_make_one_run(resin_scene(), {"greyscale", "sl1s"}, "resin");
}

TEST(StackParts, AStackOnlyJobAndADamagedPartAreSlicedAgainWhereNeeded) {
  const Scene scene = box_scene();
  const Slicer slicer(scene, {});
  JobParams one = parts_params("only-one", {"tiff"}), sharded = parts_params("only-shards", {"tiff"});
  run_slice_job(slicer, one);
  const JobManifest merged = slice_shards_and_merge(slicer, sharded, 2);
  // A stack-only job's shards write nothing but their parts (and the sheet of materials).
  for (const ManifestFile& f : merged.files)
    EXPECT_TRUE(f.layer == 0 ? f.name == "materials.csv" : detail::is_stack_part(f.name)) << f.name;
  // One part damaged: its layer is sliced again, the rest come from the parts.
  const fs::path damaged = sharded.output_dir / merged.files.back().name;
  std::ofstream(damaged, std::ios::binary | std::ios::app) << "x";
  const JobStats resumed = test::slice_resumed(slicer, sharded);
  EXPECT_EQ(resumed.layers.size(), 1u);
  EXPECT_FALSE(fs::exists(sharded.output_dir / "stack_parts"));  // the damaged one too
  EXPECT_EQ(test::read_bytes(one.output_dir / "manifest.json"), test::read_bytes(sharded.output_dir / "manifest.json"));
  EXPECT_EQ(test::read_bytes(one.output_dir / "tiff/stack.tif"),
            test::read_bytes(sharded.output_dir / "tiff/stack.tif"));
  fs::remove_all(one.output_dir);
  fs::remove_all(sharded.output_dir);
}

TEST(StackParts, AnInterruptedShardKeepsItsParts) {
  const Scene scene = box_scene();
  const Slicer slicer(scene, {});
  JobParams one = parts_params("stop-one", {"voxelprint", "gcvf"}),
            p = parts_params("stop-shards", {"voxelprint", "gcvf"});
  run_slice_job(slicer, one);
  p.shard_index = 1, p.shard_count = 2;
  const JobStats stopped = test::slice_until_stopped(slicer, p, 2);
  ASSERT_TRUE(stopped.interrupted);
  const JobManifest m = read_manifest(p.output_dir / "manifest.shard-1-of-2.json");
  EXPECT_EQ(m.message.find("slices every layer again"), std::string::npos) << m.message;  // a shard keeps them
  const JobStats rest = test::slice_resumed(slicer, p);
  EXPECT_EQ(rest.layers_kept, static_cast<int>(stopped.layers.size()));
  p.shard_index = 2;
  run_slice_job(slicer, p);
  merge_shards(p.output_dir);
  p.shard_index = p.shard_count = 1;
  test::slice_resumed(slicer, p);
  expect_same_files(one.output_dir, p.output_dir);
  fs::remove_all(one.output_dir);
  fs::remove_all(p.output_dir);
}

TEST(StackParts, APartThatDoesNotFitTheJobIsRefused) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-stack-parts-{}-read", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir / "stack_parts");
  const std::vector<std::uint8_t> labels = {0, 1, 2, 3, 0, 1};
  write_png_gray8(dir / "stack_parts/a.labels.png", 3, 2, labels);
  write_png_gray8(dir / "stack_parts/a.grey.png", 3, 2, labels);
  const detail::StackPart part =
      detail::read_stack_part(dir, {"stack_parts/a.labels.png", "stack_parts/a.grey.png"}, 3, 2, 3);
  EXPECT_EQ(part.labels.at(2, 0), 2);
  EXPECT_EQ(part.grey.at(0, 1), 3);
  const detail::StackPart no_grey = detail::read_stack_part(dir, {"stack_parts/a.labels.png"}, 3, 2, 3);
  EXPECT_TRUE(no_grey.grey.values().empty());
  const auto refused = [&](std::vector<std::string> names, int w, int h, int materials, const std::string& says) {
    try {
      detail::read_stack_part(dir, names, w, h, materials);
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused({"stack_parts/a.labels.png"}, 3, 2, 2, "label 3 in a stack part of a job of 2 materials");
  refused({"stack_parts/a.labels.png"}, 2, 3, 3, "a stack part of 3 x 2 px, the job's layers are 2 x 3");
  refused({"stack_parts/a.grey.png"}, 3, 2, 3, "no stack_parts/*.labels.png among the layer's stack parts");
  std::ofstream(dir / "stack_parts/b.labels.png") << "not a png";
  refused({"stack_parts/b.labels.png"}, 3, 2, 3, "b.labels.png");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace trivox
