// Job estimates against the job itself, and the up-front refusals.
#include "trivox/job/job_estimate.h"

#include <unistd.h>

#include <filesystem>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/output/detail/vdb_stack.h"

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

  EXPECT_EQ(e.whole_job_files, 1);  // materials.csv
  run_slice_job(slicer, p);
  std::uint64_t file_bytes = 0, manifest_bytes = 0, stats_bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(p.output_dir)) {
    if (!entry.is_regular_file()) continue;
    if (entry.path().extension() == ".png" || entry.path().extension() == ".csv") file_bytes += entry.file_size();
    if (entry.path().filename() == "manifest.json") manifest_bytes = entry.file_size();
    if (entry.path().filename() == "stats.json") stats_bytes = entry.file_size();
  }
  // Every layer was sampled, so only the integer mean, the manifest allowance and the
  // digits of stats.json's timings differ.
  const std::uint64_t allowance = 140u * 91u;
  ASSERT_GT(stats_bytes, 0u);
  EXPECT_LE(e.output_bytes, file_bytes + stats_bytes + stats_bytes / 20 + allowance);
  EXPECT_GE(e.output_bytes + static_cast<std::uint64_t>(model_layers) + stats_bytes / 20,
            file_bytes + stats_bytes + allowance);
  EXPECT_LE(manifest_bytes, allowance + 2000u);  // the allowance covers the real manifest
  fs::remove_all(p.output_dir);
}

// A tall job of small layers (the chalice: 901 layers, most of them a thin stem) writes a
// stats.json comparable to its images; the estimate counts it, from the job's own writer.
TEST(JobEstimate, StatsJsonIsCounted) {
  Scene scene = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {0.3, 0.3, 3}))}, 2);
  scene.source = "estimate-tall-scene";
  const Slicer slicer(scene, {});
  ASSERT_GE(slicer.layout().num_layers, 90);
  JobParams p;
  p.output_dir = fs::temp_directory_path() / fmt::format("trivox-estimate-stats-{}", ::getpid());
  fs::remove_all(p.output_dir);
  p.threads = 2;
  const JobEstimate e = estimate_job(slicer, p, EstimateParams{3});
  run_slice_job(slicer, p);
  std::uint64_t all_bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(p.output_dir))
    if (entry.is_regular_file()) all_bytes += entry.file_size();
  const std::uint64_t stats_bytes = fs::file_size(p.output_dir / "stats.json");
  EXPECT_GT(stats_bytes, all_bytes / 4) << "stats.json is not a large part of this job";
  // stats.json within 5% (its timings' digits vary), the whole output within 10%.
  EXPECT_NEAR(static_cast<double>(e.stats_bytes), static_cast<double>(stats_bytes),
              0.05 * static_cast<double>(stats_bytes));
  EXPECT_NEAR(static_cast<double>(e.output_bytes), static_cast<double>(all_bytes),
              0.10 * static_cast<double>(all_bytes));
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

// A job whose memory estimate already exceeds the limit slices no sample layer (which
// would build the layer it cannot afford) and is refused on memory.
TEST(JobEstimate, AJobTooLargeForMemorySlicesNoSampleLayer) {
  const Scene scene = estimate_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  const JobEstimate unlimited = estimate_job(slicer, p, EstimateParams{2});
  EXPECT_EQ(unlimited.sampled_layers, 2);
  p.memory_limit_bytes = unlimited.peak_memory_bytes / 2;
  const JobEstimate e = estimate_job(slicer, p, EstimateParams{2});
  EXPECT_EQ(e.sampled_layers, 0);
  EXPECT_EQ(e.output_bytes, 0u);
  EXPECT_THROW(check_job_fits(e, p), Error);
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
    check_job_fits(e, p);
    FAIL() << "a job larger than any disk was accepted";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("trivox-no-such-folder"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("disk"), std::string::npos) << err.what();
  }
  e.output_bytes = 1;
  p.memory_limit_bytes = 1000;
  EXPECT_NO_THROW(check_job_fits(e, p));
  p.memory_limit_bytes = 999;
  try {
    check_job_fits(e, p);
    FAIL() << "a job over the memory limit was accepted";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("memory"), std::string::npos) << err.what();
  }
  ASSERT_TRUE(free_disk_bytes(fs::temp_directory_path()).has_value());
  EXPECT_GT(*free_disk_bytes(fs::temp_directory_path()), 0u);
}

// The stack outputs write nothing per layer: their files, their spools and the memory they
// hold must still be counted. With every model layer sampled, the TIFF and the package are
// predicted to within their headers, the OpenVDB file and grids (measured on grids built
// from the samples, slab by slab) to within a factor of two.
TEST(JobEstimate, StackOutputsAreCountedOnDiskAndInMemory) {
  const Scene scene = estimate_scene();
  const Slicer slicer(scene, {});
  const int model_layers = slicer.layout().num_layers;
  JobParams plain;
  plain.formats = {"voxelprint"};
  plain.threads = 2;
  const JobEstimate base = estimate_job(slicer, plain, EstimateParams{model_layers});
  EXPECT_EQ(base.whole_job_files, 1);  // materials.csv
  EXPECT_EQ(base.scratch_bytes, 0u);
  EXPECT_EQ(base.stack_memory_bytes, 0u);
  for (const std::string format : {"tiff", "vdb", "gcvf"}) {
    SCOPED_TRACE(format);
    JobParams p;
    p.output_dir = fs::temp_directory_path() / fmt::format("trivox-estimate-stack-{}-{}", ::getpid(), format);
    fs::remove_all(p.output_dir);
    p.formats = {format};
    p.threads = 2;
    const JobEstimate e = estimate_job(slicer, p, EstimateParams{model_layers});
    EXPECT_EQ(e.files_per_layer, 0);
    EXPECT_EQ(e.whole_job_files, 2);  // materials.csv and the stack
    EXPECT_GT(e.scratch_bytes, 0u);
    EXPECT_GT(e.stack_memory_bytes, 0u);
    EXPECT_GE(e.peak_memory_bytes, e.stack_memory_bytes);

    run_slice_job(slicer, p);
    const std::string stack = format == "tiff"  ? "tiff/stack.tif"
                              : format == "vdb" ? "vdb/stack.vdb"
                                                : "gcvf/stack.gcvf";
    const std::uint64_t stack_bytes = fs::file_size(p.output_dir / stack);
    const std::uint64_t rest =
        fs::file_size(p.output_dir / "materials.csv") + fs::file_size(p.output_dir / "manifest.json");
    const std::uint64_t allowance = 140u * 2u;  // the manifest's, for two files
    const std::uint64_t stats_bytes = fs::file_size(p.output_dir / "stats.json");
    EXPECT_NEAR(static_cast<double>(e.stats_bytes), static_cast<double>(stats_bytes),
                0.05 * static_cast<double>(stats_bytes));
    const std::uint64_t real = stack_bytes + fs::file_size(p.output_dir / "materials.csv") + allowance + e.stats_bytes;
    EXPECT_LE(rest, fs::file_size(p.output_dir / "materials.csv") + allowance + 2000u);
    if (format == "vdb") {
      EXPECT_GE(e.output_bytes, real / 2);
      EXPECT_LE(e.output_bytes, real * 2);
      // The grids as OpenVDB holds them after reading the file back.
      std::uint64_t grid_memory = 0;
      for (const VdbGridInfo& g : read_vdb_grid_info(p.output_dir / stack)) grid_memory += g.memory_bytes;
      EXPECT_GE(e.stack_memory_bytes, grid_memory / 2) << grid_memory;
      EXPECT_LE(e.stack_memory_bytes, grid_memory * 2 + 1000000u) << grid_memory;
    } else {
      // Every layer was sampled: the integer mean and the headers' allowances differ.
      EXPECT_GE(e.output_bytes + static_cast<std::uint64_t>(model_layers), real) << "real " << real;
      EXPECT_LE(e.output_bytes, real + real / 50 + 2000u) << "real " << real;
      // The spool held every page or image the file holds.
      EXPECT_LE(e.scratch_bytes, stack_bytes);
      EXPECT_GE(e.scratch_bytes + 2000u * 30u, stack_bytes);
    }
    fs::remove_all(p.output_dir);
  }
}

// The up-front checks take the stack outputs into account: a disk with one byte less than
// the layer files, the stack file and its spool is refused; a memory limit that a plain job
// just meets refuses the same job with OpenVDB grids.
TEST(JobEstimate, RefusesStackOutputsTheDiskOrMemoryCannotTake) {
  const Scene scene = estimate_scene();
  const Slicer slicer(scene, {});
  JobParams p;
  p.output_dir = fs::temp_directory_path() / "trivox-estimate-refusal";
  p.threads = 1;
  p.formats = {"voxelprint"};
  const JobEstimate q = estimate_job(slicer, p, EstimateParams{2});  // first: the process only grows
  JobParams plain = p;
  p.formats = {"voxelprint", "vdb"};
  const JobEstimate e = estimate_job(slicer, p, EstimateParams{2});
  const std::uint64_t disk = e.output_bytes + e.scratch_bytes;
  EXPECT_NO_THROW(check_job_fits(e, p, disk));
  try {
    check_job_fits(e, p, disk - 1);
    FAIL() << "a job one byte larger than the disk was accepted";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("trivox-estimate-refusal"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("spool files"), std::string::npos) << err.what();
  }
  // Without its spool the output alone would fit: the spool is what the disk lacks.
  EXPECT_GT(e.scratch_bytes, 1u);
  // The plain job's peak as the limit: it just fits; the grids put the other over it.
  const std::uint64_t limit = q.peak_memory_bytes;
  plain.memory_limit_bytes = limit;
  p.memory_limit_bytes = limit;
  EXPECT_NO_THROW(check_job_fits(q, plain, std::nullopt));
  try {
    check_job_fits(e, p, std::nullopt);
    FAIL() << "the OpenVDB grids were not counted against the memory limit";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("for the stack outputs"), std::string::npos) << err.what();
  }
}

// The disk check measures the file system a new folder will be made on, also for a relative
// path none of whose folders exists yet (then the current folder's).
TEST(JobEstimate, FreeDiskOfAFolderThatDoesNotExistYet) {
  const auto here = free_disk_bytes(".");
  ASSERT_TRUE(here.has_value());
  for (const char* dir : {"trivox-no-such-folder/out", "trivox-no-such-folder", ""}) {
    const auto free = free_disk_bytes(dir);
    ASSERT_TRUE(free.has_value()) << dir;
    // The same file system; other work may write to it between the two calls.
    EXPECT_NEAR(static_cast<double>(*free), static_cast<double>(*here), 1e9) << dir;
  }
  EXPECT_TRUE(free_disk_bytes("/trivox-no-such-folder/out").has_value());
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
