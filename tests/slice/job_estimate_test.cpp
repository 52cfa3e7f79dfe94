// Job estimates against the job itself, and the up-front refusals.
#include "trivox/slice/job_estimate.h"

#include <filesystem>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "trivox/error.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

Scene estimate_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {6, 3, 0.2}))}, 2);
  s.source = "estimate-scene";
  return s;
}

TEST(JobEstimate, SamplingEveryLayerPredictsTheOutputSizeOfTheJob) {
  const Scene scene = estimate_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-estimate-test";
  fs::remove_all(p.output_dir);
  p.formats = {"voxelprint", "bitmaps"};
  const int model_layers = slicer.layout().num_layers;
  const JobEstimate e = estimate_job(slicer, p, EstimateParams{model_layers});
  EXPECT_EQ(e.model_layers, model_layers);
  EXPECT_EQ(e.job_layers, 30);
  EXPECT_EQ(e.padded_layers, 30 - model_layers);
  EXPECT_EQ(e.files_per_layer, 3);
  EXPECT_EQ(e.pixels, static_cast<std::int64_t>(e.width_px) * e.height_px * 30);
  EXPECT_GT(e.peak_memory_bytes, static_cast<std::uint64_t>(e.width_px) * static_cast<std::uint64_t>(e.height_px));

  run_slice_job(slicer, p);
  std::uint64_t layer_bytes = 0, manifest_bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(p.output_dir)) {
    if (!entry.is_regular_file()) continue;
    if (entry.path().extension() == ".png") layer_bytes += entry.file_size();
    if (entry.path().filename() == "manifest.json") manifest_bytes = entry.file_size();
  }
  // Every layer was sampled, so only the integer mean and the manifest allowance differ.
  const std::uint64_t allowance = 140u * 90u;
  EXPECT_LE(e.output_bytes, layer_bytes + allowance);
  EXPECT_GE(e.output_bytes + static_cast<std::uint64_t>(model_layers), layer_bytes + allowance);
  EXPECT_LE(manifest_bytes, allowance + 2000u);  // the allowance covers the real manifest
  fs::remove_all(p.output_dir);
}

TEST(JobEstimate, AShardEstimatesItsOwnLayers) {
  const Scene scene = estimate_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  p.shard_index = 2;
  p.shard_count = 4;
  const JobEstimate e = estimate_job(slicer, p, EstimateParams{0});
  EXPECT_EQ(e.job_layers, 8);  // layers 2, 6, ..., 30 of 30
  EXPECT_EQ(e.sampled_layers, 0);
}

TEST(JobEstimate, RefusesWhatTheDiskOrMemoryCannotTake) {
  JobEstimate e;
  e.sampled_layers = 1;
  e.job_layers = 10;
  e.files_per_layer = 1;
  e.output_bytes = std::numeric_limits<std::uint64_t>::max() / 2;
  e.peak_memory_bytes = 1000;
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-no-such-folder" / "out";
  try {
    check_job_fits(e, p, std::nullopt);
    FAIL() << "a job larger than any disk was accepted";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("trivox-no-such-folder"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("disk"), std::string::npos) << err.what();
  }
  e.output_bytes = 1;
  EXPECT_NO_THROW(check_job_fits(e, p, std::uint64_t{1000}));
  try {
    check_job_fits(e, p, std::uint64_t{999});
    FAIL() << "a job over the memory limit was accepted";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("memory"), std::string::npos) << err.what();
  }
  ASSERT_TRUE(free_disk_bytes(fs::temp_directory_path()).has_value());
  EXPECT_GT(*free_disk_bytes(fs::temp_directory_path()), 0u);
}

TEST(JobEstimate, ByteText) {
  EXPECT_EQ(byte_text(17), "17 B");
  EXPECT_EQ(byte_text(12345), "12.3 kB");
  EXPECT_EQ(byte_text(456000000), "456.0 MB");
  EXPECT_EQ(byte_text(1230000000), "1.23 GB");
}

TEST(JobEstimate, ThreadTextAgreesInNumber) {
  EXPECT_EQ(thread_text(1), "1 thread");
  EXPECT_EQ(thread_text(2), "2 threads");
}

}  // namespace
}  // namespace trivox
