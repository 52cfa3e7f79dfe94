// SliceJob (job/slice_job.h), the one job that `trivox slice` and the Python module run: the
// folder is locked before the scene is read, put back as found when the job fails on its
// input, the scene is read through the folder's construction cache, a stack without the
// object is an EmptyResultError, and the statistics are summed once and written by one list.
// Also: `merge` takes the folder's lock before it writes.
#include <filesystem>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job_folder.h"
#include "trivox/job/slice_job.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// A slanted slab a nanometre thick: its bitmap has pixels, but no pixel centre lies in it.
const char* const kSheet = R"({"version": 1, "units": "mm", "printer": "j750-hm",
 "materials": [{"name": "VeroCyan"}],
 "cells": [{"name": "c", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [[0, 0.0123, 0], [4, 1.4923, 0], [0, 0.012301, 0], [4, 1.492301, 0],
              [0, 0.0123, 4], [4, 1.4923, 4], [0, 0.012301, 4], [4, 1.492301, 4]]},
   "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}]})";

class SliceJobTest : public ::testing::Test {
 protected:
  void SetUp() override {
    write_text(dir_.path() / "tube.json", kRevolvedTubeScene);
    write_tube_profile(dir_.path() / "profile.itd", 8);
  }
  SliceJobParams params(const fs::path& out) const {
    SliceJobParams p;
    p.job.output_dir = out;
    p.job.first_layer = 0;
    p.job.last_layer = 2;
    p.job.min_layers = 0;
    p.job.threads = 1;
    return p;
  }
  // Reads `scene` through a job into `out`, slices it and returns the job's statistics.
  JobStats run(const fs::path& out, const fs::path& scene, int* cache_hits = nullptr) const {
    SliceJob job(params(out));
    const Scene s = job.read_scene(scene);
    if (cache_hits) *cache_hits = job.cache_hits();
    const Slicer slicer(s, job.slice_params({}));
    job.check_fits(slicer);
    JobStats stats = job.run(slicer);
    job.check_result(stats);
    return stats;
  }
  ScratchDir dir_;
};

TEST_F(SliceJobTest, ASecondJobIntoALockedFolderIsRefusedBeforeTheSceneIsRead) {
  const fs::path out = dir_.path() / "out";
  SliceJob first(params(out));
  // The second job names no readable scene: refused on the lock, it never gets to read one.
  try {
    SliceJob second(params(out));
    (void)second.read_scene(dir_.path() / "no-such-scene.json");
    FAIL() << "a second job into a locked folder was let in";
  } catch (const IoError& e) {
    FAIL() << "the scene was read before the lock was taken: " << e.what();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(out.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(out / ".trivox.lock"));
}

TEST_F(SliceJobTest, AFailedSceneLeavesAnAbsentOrEmptyFolderAsItWas) {
  write_text(dir_.path() / "bad.json", "{\"version\": 1,");
  const fs::path absent = dir_.path() / "absent", empty = dir_.path() / "empty", full = dir_.path() / "full";
  fs::create_directories(empty);
  fs::create_directories(full);
  write_text(full / "mine.txt", "kept");
  for (const fs::path& out : {absent, empty, full}) {
    SCOPED_TRACE(out.string());
    EXPECT_THROW(run(out, dir_.path() / "bad.json"), InputError);
  }
  EXPECT_FALSE(fs::exists(absent));
  ASSERT_TRUE(fs::is_directory(empty));
  EXPECT_TRUE(fs::is_empty(empty));
  // A folder that held files is not the job's to empty; the lock files go with the lock.
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(full)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"mine.txt"}));
}

TEST_F(SliceJobTest, TheSecondRunTakesTheConstructedVolumeFromTheCache) {
  const fs::path out = dir_.path() / "out";
  int hits = -1;
  const JobStats first = run(out, dir_.path() / "tube.json", &hits);
  EXPECT_EQ(hits, 0);
  EXPECT_TRUE(fs::is_directory(out / ".trivox-cache"));
  const JobStats second = run(out, dir_.path() / "tube.json", &hits);
  EXPECT_EQ(hits, 1);
  EXPECT_EQ(second.total.pixels_inside, first.total.pixels_inside);
  EXPECT_GT(first.total.pixels_inside, 0);
  // Disabled: neither read nor written.
  SliceJobParams p = params(dir_.path() / "uncached");
  p.construction_cache = false;
  SliceJob job(std::move(p));
  (void)job.read_scene(dir_.path() / "tube.json");
  EXPECT_EQ(job.cache_hits(), 0);
  EXPECT_FALSE(fs::exists(dir_.path() / "uncached" / ".trivox-cache"));
}

TEST_F(SliceJobTest, AStackWithoutTheObjectIsAnEmptyResultErrorAfterItsFilesAreWritten) {
  write_text(dir_.path() / "sheet.json", kSheet);
  const fs::path out = dir_.path() / "out";
  EXPECT_THROW(run(out, dir_.path() / "sheet.json"), EmptyResultError);
  // The files stay: the job itself is complete.
  EXPECT_EQ(nlohmann::json::parse(read_text(out / "manifest.json")).at("status"), "complete");
  SliceJobParams p = params(dir_.path() / "allowed");
  p.allow_empty = true;
  SliceJob job(std::move(p));
  const Scene s = job.read_scene(dir_.path() / "sheet.json");
  const Slicer slicer(s, job.slice_params({}));
  const JobStats stats = job.run(slicer);
  EXPECT_TRUE(job.empty_result(stats));
  EXPECT_NO_THROW(job.check_result(stats));
}

// The job's statistics are summed once (JobStats::total) and stats.json's "total" holds every
// count visit_layer_stats names, with the values of that sum.
TEST_F(SliceJobTest, StatsJsonWritesTheOneSumByTheOneList) {
  const fs::path out = dir_.path() / "out";
  const JobStats stats = run(out, dir_.path() / "tube.json");
  LayerStats sum;
  for (const LayerStats& s : stats.layers) sum += s;
  EXPECT_EQ(stats.total.pixels_inside, sum.pixels_inside);
  EXPECT_EQ(stats.total.candidates, sum.candidates);
  const nlohmann::json doc = nlohmann::json::parse(read_text(out / "stats.json"));
  int named = 0;
  visit_layer_stats(stats.total, LayerStatsPart::kCounts, [&](std::string_view name, const auto& value) {
    ++named;
    ASSERT_TRUE(doc.at("total").contains(std::string(name))) << name;
    EXPECT_EQ(doc.at("total").at(std::string(name)), nlohmann::json(value)) << name;
  });
  EXPECT_EQ(named, static_cast<int>(kTraceCounterFields.size()) + 5);
  for (const auto& layer : doc.at("layers")) EXPECT_EQ(layer.size(), kTraceCounterFields.size() + 11);
}

// merge writes manifest.json, so it holds the folder's lock: refused while a shard runs.
TEST_F(SliceJobTest, MergeIsRefusedWhileAShardHoldsTheFolder) {
  const fs::path out = dir_.path() / "out";
  for (int shard = 1; shard <= 2; ++shard) {
    SliceJobParams p = params(out);
    p.job.shard_index = shard;
    p.job.shard_count = 2;
    SliceJob job(std::move(p));
    const Scene s = job.read_scene(dir_.path() / "tube.json");
    (void)job.run(Slicer(s, job.slice_params({})));
  }
  {
    const JobFolderLock running(out, 1, 2);
    try {
      (void)merge_shards(out);
      FAIL() << "merged while shard 1 holds the folder";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(out.string()), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::exists(out / "manifest.shard-1-of-2.json"));
  }
  EXPECT_EQ(merge_shards(out).status, JobStatus::kComplete);
  EXPECT_FALSE(fs::exists(out / ".trivox.lock"));
}

}  // namespace
}  // namespace trivox::test
