// Safe long jobs in-process: the manifest, stopping at random layer counts and resuming,
// refusing to resume a different job, shards and their merge, and verify.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/error.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/job/manifest.h"
#include "trivox/job/printed_extent.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/png_io.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

fs::path fresh_dir(const std::string& name) {
  // The process id keeps test processes that CTest runs side by side apart.
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-resume-test-{}-{}", ::getpid(), name);
  fs::remove_all(dir);
  return dir;
}

using test::folder_bytes;

// Two materials, 15 model layers padded to 30 job layers.
Scene small_scene() {
  Scene s = test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {6, 3, 0.2}))}, 2);
  s.cells.push_back(test::constant_cell(
      Volume(test::annulus_sector(1, 2.5, 0.2).spline().transformed([](std::span<double> q) { q[0] += 3; })), 0, 2,
      "ring"));
  s.source = "small-scene";
  s.source_sha256 = sha256_hex("small-scene v1");
  return s;
}

JobParams params_for(const fs::path& dir, int threads) {
  JobParams p;
  p.output_dir = dir;
  p.threads = threads;
  p.formats = {"voxelprint", "bitmaps"};
  p.manifest_interval_seconds = 0;
  return p;
}

class JobResume : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(small_scene());
    slicer_ = new Slicer(*scene_, {});
    reference_dir_ = new fs::path(fresh_dir("reference"));
    reference_printed_ = new PrintedExtent(run_slice_job(*slicer_, params_for(*reference_dir_, 2)).printed);
    reference_ = new std::map<std::string, std::string>(folder_bytes(*reference_dir_));
  }
  static void TearDownTestSuite() {
    delete reference_;
    delete reference_printed_;
    fs::remove_all(*reference_dir_);
    delete reference_dir_;
    delete slicer_;
    delete scene_;
  }
  static Scene* scene_;
  static Slicer* slicer_;
  static fs::path* reference_dir_;
  static std::map<std::string, std::string>* reference_;
  static PrintedExtent* reference_printed_;
};
Scene* JobResume::scene_ = nullptr;
Slicer* JobResume::slicer_ = nullptr;
fs::path* JobResume::reference_dir_ = nullptr;
std::map<std::string, std::string>* JobResume::reference_ = nullptr;
PrintedExtent* JobResume::reference_printed_ = nullptr;

void expect_same_extent(const PrintedExtent& a, const PrintedExtent& b, const std::string& what) {
  EXPECT_EQ(std::tie(a.col_lo, a.col_hi, a.row_lo, a.row_hi, a.layer_lo, a.layer_hi),
            std::tie(b.col_lo, b.col_hi, b.row_lo, b.row_hi, b.layer_lo, b.layer_hi))
      << what << ": columns " << a.col_lo << "-" << a.col_hi << " / " << b.col_lo << "-" << b.col_hi << ", layers "
      << a.layer_lo << "-" << a.layer_hi << " / " << b.layer_lo << "-" << b.layer_hi;
}

TEST_F(JobResume, ManifestListsEveryFileWithItsSizeAndHash) {
  const JobManifest m = read_manifest(*reference_dir_ / "manifest.json");
  EXPECT_EQ(m.status, JobStatus::kComplete);
  EXPECT_EQ(m.total_layers, 30);
  ASSERT_EQ(m.inputs.size(), 1u);
  EXPECT_EQ(m.inputs[0].sha256, scene_->source_sha256);
  // One RGBA layer and one bitmap per material for each of the 30 layers, and materials.csv.
  ASSERT_EQ(m.files.size(), 30u * 3u + 1u);
  std::set<int> layers;
  for (const ManifestFile& f : m.files) {
    const FileDigest d = sha256_file(*reference_dir_ / f.name);
    EXPECT_EQ(d.bytes, f.bytes) << f.name;
    EXPECT_EQ(d.sha256, f.sha256) << f.name;
    layers.insert(f.layer);
  }
  EXPECT_EQ(layers.size(), 31u);  // layers 1 to 30, and 0 for materials.csv
  // The file lists the manifest and the folder agree.
  EXPECT_EQ(reference_->size(), m.files.size() + 1);
  EXPECT_TRUE(verify_output(*reference_dir_).ok());
  // Text round trip.
  EXPECT_EQ(manifest_text(parse_manifest(manifest_text(m), "m")), manifest_text(m));
}

// A name holding NUL or another control character (an input's, a cell's, a file's) is refused
// wherever a manifest is read, and the message shows it escaped, whole: a NUL would otherwise
// cut the message and let a changed name pass.
TEST_F(JobResume, ManifestNamesWithControlCharactersAreRefusedAndShownEscaped) {
  const JobManifest m = read_manifest(*reference_dir_ / "manifest.json");
  const std::string text = manifest_text(m);
  const std::string file_name = "\"" + m.files.back().name + "\"";
  ASSERT_NE(text.find(file_name), std::string::npos);
  for (const std::string& inserted : {std::string("\\u0000"), std::string("\\n"), std::string("\\u001b[2J")}) {
    std::string bad = text;
    bad.insert(bad.find(file_name) + 2, inserted);
    try {
      (void)parse_manifest(bad, "the manifest");
      ADD_FAILURE() << "a name holding " << inserted << " was taken";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("/name"), std::string::npos) << what;
      EXPECT_NE(what.find("control character"), std::string::npos) << what;
      EXPECT_EQ(what.find('\0'), std::string::npos);
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find("names hold none"), std::string::npos) << what;  // not cut at the NUL
    }
  }
}

// verify and merge read their stop flag before each file (the program's SIGINT and SIGTERM).
TEST_F(JobResume, VerifyStopsAtItsStopFlag) {
  std::atomic<bool> stop{true};
  EXPECT_THROW((void)verify_output(*reference_dir_, &stop), CancelledError);
  EXPECT_THROW((void)merge_shards(*reference_dir_, &stop), Error);  // no shards: refused before any file
  stop = false;
  EXPECT_TRUE(verify_output(*reference_dir_, &stop).ok());
}

// The manifest keeps each layer's printed extent (only layers with a material), so that a
// resumed job reports the whole job's; a damaged list is refused with its field named.
TEST_F(JobResume, TheManifestKeepsEachLayersPrintedExtent) {
  const JobManifest m = read_manifest(*reference_dir_ / "manifest.json");
  ASSERT_EQ(m.printed.size(), 15u);  // the 15 model layers; the padding layers are empty
  PrintedExtent whole;
  for (const ManifestPrinted& p : m.printed) {
    EXPECT_LE(p.col_lo, p.col_hi);
    whole.add(printed_extent(p, p.layer - 1));
  }
  expect_same_extent(whole, *reference_printed_, "the manifest's layers");
  const std::string text = manifest_text(m);
  for (const auto& [from, to, rule] :
       {std::tuple<std::string, std::string, std::string>{"\"columns\":[", "\"columns\":[-4,", "/printed/0/columns"},
        {"\"rows\":[", "\"rows\":[9999,1,", "/printed/0/rows"},
        {"{\"layer\":2,\"columns", "{\"layer\":1,\"columns", "listed twice"},
        {"{\"layer\":1,\"columns", "{\"layer\":31,\"columns", "/printed/0/layer"}}) {
    std::string bad = text;
    const std::size_t at = bad.find(from, bad.find("\"printed\""));
    ASSERT_NE(at, std::string::npos) << from;
    bad.replace(at, from.size(), to);
    try {
      (void)parse_manifest(bad, "the manifest");
      ADD_FAILURE() << to << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(rule), std::string::npos) << e.what();
    }
  }
}

// A job whose outputs are all written when it completes keeps no layer: the interruption and
// the manifest say that --resume slices every layer again; beside a per-layer format, that it
// slices the kept ones once more.
TEST_F(JobResume, AnInterruptedStackJobSaysResumeSlicesItsLayersAgain) {
  JobParams p = params_for(fresh_dir("stack-note"), 1);
  EXPECT_EQ(stack_resume_note(p), "");
  p.formats = {"gcvf"};
  EXPECT_EQ(stack_resume_note(p),
            "gcvf is written only when the job completes and keeps no finished layer, so --resume slices every layer "
            "again");
  p.formats = {"voxelprint", "tiff"};
  p.preview_layers = {3};  // a layer's preview is one of its files, kept with it
  EXPECT_EQ(stack_resume_note(p),
            "--resume keeps the finished layers of voxelprint and slices them once more for tiff, written only when "
            "the job completes");
  // A shard keeps its layers for them (tests/job/stack_parts_test.cpp).
  p.shard_count = 2;
  EXPECT_EQ(stack_resume_note(p), "");
  p.shard_count = 1;
  p.formats = {"gcvf"};
  p.preview_layers.clear();
  std::atomic<bool> stop{true};
  p.stop = &stop;
  const JobStats st = run_slice_job(*slicer_, p);
  EXPECT_TRUE(st.interrupted);
  const JobManifest m = read_manifest(p.output_dir / "manifest.json");
  EXPECT_EQ(m.status, JobStatus::kInterrupted);
  EXPECT_NE(m.message.find("--resume slices every layer again"), std::string::npos) << m.message;
  fs::remove_all(p.output_dir);
}

TEST_F(JobResume, StoppedAtTwentyRandomLayerCountsAndResumedEndsByteIdentical) {
  std::mt19937 rng(20261123);
  int interrupted = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const fs::path dir = fresh_dir(fmt::format("trial{}", trial));
    std::atomic<bool> stop{false};
    const int after = std::uniform_int_distribution<int>(0, 26)(rng);
    if (after == 0) stop = true;
    test::StopAfterLayers sink(&stop, after);
    JobParams p = params_for(dir, 1 + trial % 3);
    p.stop = &stop;
    // Half the trials keep the manifest lagging (written only at the start and the end of a
    // run), as after a kill between a layer's rename and the manifest's next update.
    p.manifest_interval_seconds = trial % 2 == 0 ? 0.0 : 1e9;
    const JobStats first = run_slice_job(*slicer_, p, &sink);
    EXPECT_TRUE(first.interrupted) << "trial " << trial;
    interrupted += first.interrupted;
    EXPECT_EQ(read_manifest(dir / "manifest.json").status, JobStatus::kInterrupted);
    // No temporary or truncated file: every PNG under a final name decodes.
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      if (!e.is_regular_file()) continue;
      EXPECT_FALSE(is_atomic_temporary_name(e.path().filename().string())) << e.path();
      if (e.path().extension() == ".png") {
        EXPECT_NO_THROW(read_png_rgba(e.path())) << e.path();
      }
    }
    // A hard kill can leave a temporary file and a manifest that lags the files on disk.
    JobManifest lagging = read_manifest(dir / "manifest.json");
    const std::size_t drop = std::min(lagging.files.size(), std::size_t{3} * (trial % 3));
    lagging.files.resize(lagging.files.size() - drop);
    lagging.status = JobStatus::kRunning;
    write_manifest(dir / "manifest.json", lagging);
    std::ofstream(dir / "slice_00002.png.tmp-99999-7") << "partial";

    JobParams again = params_for(dir, 1 + (trial + 1) % 3);
    again.resume = true;
    const JobStats second = run_slice_job(*slicer_, again);
    EXPECT_FALSE(second.interrupted);
    EXPECT_EQ(second.layers_kept + static_cast<int>(second.files.size()) / 3, 30) << "trial " << trial;
    // The printed extent is the whole job's, the layers kept included.
    expect_same_extent(second.printed, *reference_printed_, fmt::format("trial {}", trial));
    EXPECT_EQ(folder_bytes(dir), *reference_) << "trial " << trial << " stopped after " << after;
    fs::remove_all(dir);
  }
  EXPECT_EQ(interrupted, 20);
}

TEST_F(JobResume, RefusesToResumeADifferentJob) {
  const fs::path dir = fresh_dir("refuse");
  std::atomic<bool> stop{true};
  JobParams p = params_for(dir, 1);
  p.stop = &stop;
  run_slice_job(*slicer_, p);

  SliceParams other_params;
  other_params.tracing = TracingStrategy::kNone;
  const Slicer other(*scene_, other_params);
  JobParams again = params_for(dir, 1);
  again.resume = true;
  try {
    run_slice_job(other, again);
    FAIL() << "resumed with another tracing strategy";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("tracing"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("manifest.json"), std::string::npos) << e.what();
  }
  Scene changed = *scene_;
  changed.source_sha256 = sha256_hex("small-scene v2");
  const Slicer changed_slicer(changed, {});
  try {
    run_slice_job(changed_slicer, again);
    FAIL() << "resumed with a changed scene";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has changed"), std::string::npos) << e.what();
  }
  JobParams other_format = again;
  other_format.formats = {"voxelprint"};
  EXPECT_THROW(run_slice_job(*slicer_, other_format), Error);
  // The refused attempts left the interrupted job as it was.
  EXPECT_EQ(read_manifest(dir / "manifest.json").status, JobStatus::kInterrupted);
  fs::remove_all(dir);
}

TEST_F(JobResume, ThreeShardsMergedEqualOneRun) {
  const fs::path dir = fresh_dir("shards");
  for (int i : {2, 3}) {
    JobParams p = params_for(dir, i);
    p.shard_index = i;
    p.shard_count = 3;
    run_slice_job(*slicer_, p);
  }
  EXPECT_THROW(merge_shards(dir), Error);  // shard 1 is missing
  JobParams p = params_for(dir, 1);
  p.shard_index = 1;
  p.shard_count = 3;
  const JobStats st = run_slice_job(*slicer_, p);
  EXPECT_EQ(st.files.size(), 10u * 3u + 1u);  // layers 1, 4, ..., 28 and materials.csv
  merge_shards(dir);
  EXPECT_FALSE(fs::exists(dir / "manifest.shard-1-of-3.json"));
  EXPECT_EQ(folder_bytes(dir), *reference_);
  EXPECT_TRUE(verify_output(dir).ok());
  fs::remove_all(dir);
}

TEST_F(JobResume, MergeRefusesAnIncompleteShard) {
  const fs::path dir = fresh_dir("shard-incomplete");
  std::atomic<bool> stop{true};
  for (int i : {1, 2}) {
    JobParams p = params_for(dir, 1);
    p.shard_index = i;
    p.shard_count = 2;
    if (i == 2) p.stop = &stop;
    run_slice_job(*slicer_, p);
  }
  try {
    merge_shards(dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("interrupted"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST_F(JobResume, VerifyReportsEachKindOfCorruption) {
  const fs::path dir = fresh_dir("verify");
  fs::copy(*reference_dir_, dir, fs::copy_options::recursive);
  ASSERT_TRUE(verify_output(dir).ok());
  // Same size, one byte changed; truncated; deleted.
  std::string a = read_bytes(dir / "slice_00003.png");
  a[a.size() / 2] = static_cast<char>(a[a.size() / 2] ^ 0x10);
  std::ofstream(dir / "slice_00003.png", std::ios::binary) << a;
  const std::string b = read_bytes(dir / "slice_00004.png");
  std::ofstream(dir / "slice_00004.png", std::ios::binary) << b.substr(0, b.size() / 2);
  fs::remove(dir / "bitmaps/slice_00005_m1.png");
  // A file whose hash matches its (edited) manifest entry but is not a PNG.
  JobManifest m = read_manifest(dir / "manifest.json");
  const std::string junk = "not a png";
  std::ofstream(dir / "slice_00006.png", std::ios::binary) << junk;
  for (ManifestFile& f : m.files)
    if (f.name == "slice_00006.png") {
      f.bytes = junk.size();
      f.sha256 = sha256_hex(junk);
    }
  write_manifest(dir / "manifest.json", m);

  const VerifyReport r = verify_output(dir);
  EXPECT_EQ(r.files_checked, 91);
  ASSERT_EQ(r.problems.size(), 4u);
  const auto mentions = [&](const std::string& name, const std::string& what) {
    return std::any_of(r.problems.begin(), r.problems.end(), [&](const std::string& p) {
      return p.find(name) != std::string::npos && p.find(what) != std::string::npos;
    });
  };
  EXPECT_TRUE(mentions("slice_00003.png", "SHA-256"));
  EXPECT_TRUE(mentions("slice_00004.png", "bytes"));
  EXPECT_TRUE(mentions("slice_00005_m1.png", "missing"));
  EXPECT_TRUE(mentions("slice_00006.png", "PNG"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace trivox
