// `verify` decodes every kind of file a job writes, not only hashes it: for each kind (the
// Voxel Print PNGs, the legacy BMPs, the TIFF stack, the OpenVDB grids and the GrabCAD
// package) a damaged copy whose manifest entry was updated to match - so that only decoding
// can find it - is reported, naming the file and the fault; and a damaged copy with the old
// entry is reported by its hash.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "slice/slice_fixtures.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/job/manifest.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

using test::read_bytes;

void write_bytes(const fs::path& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Replaces `name` in `dir` by `bytes` and updates its manifest entry to match them.
void replace_listed(const fs::path& dir, const std::string& name, const std::string& bytes) {
  write_bytes(dir / name, bytes);
  JobManifest m = read_manifest(dir / "manifest.json");
  bool found = false;
  for (ManifestFile& f : m.files)
    if (f.name == name) {
      f.bytes = bytes.size();
      f.sha256 = sha256_hex(bytes);
      found = true;
    }
  ASSERT_TRUE(found) << name;
  write_manifest(dir / "manifest.json", m);
}

class VerifyDecodes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(test::scene_with({test::gradient_cell(test::box_volume({0, 0, 0}, {3, 1.5, 0.12}))}, 2));
    scene_->source = "verify-scene";
    const Slicer slicer(*scene_, {});
    reference_ = new fs::path(fs::temp_directory_path() / fmt::format("trivox-verify-decode-{}", ::getpid()));
    fs::remove_all(*reference_);
    JobParams p;
    p.output_dir = *reference_;
    p.threads = 2;
    p.formats = {"voxelprint", "legacy", "tiff", "vdb", "gcvf"};
    run_slice_job(slicer, p);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*reference_);
    delete reference_;
    delete scene_;
  }
  // A fresh copy of the reference job.
  static fs::path copy(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-verify-decode-{}-{}", ::getpid(), name);
    fs::remove_all(dir);
    fs::copy(*reference_, dir, fs::copy_options::recursive);
    return dir;
  }
  static Scene* scene_;
  static fs::path* reference_;
};
Scene* VerifyDecodes::scene_ = nullptr;
fs::path* VerifyDecodes::reference_ = nullptr;

// The only problem of `r` names `name` and holds `what`.
void expect_one_problem(const VerifyReport& r, const std::string& name, const std::string& what) {
  ASSERT_EQ(r.problems.size(), 1u) << (r.problems.empty() ? "" : r.problems.front());
  EXPECT_NE(r.problems[0].find(name), std::string::npos) << r.problems[0];
  EXPECT_NE(r.problems[0].find(what), std::string::npos) << r.problems[0];
}

TEST_F(VerifyDecodes, TheReferenceJobVerifies) {
  const VerifyReport r = verify_output(*reference_);
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
  // 30 Voxel Print layers, 2 x 30 BMPs, slices.txt, the three stacks and materials.csv.
  EXPECT_EQ(r.files_checked, 30 + 60 + 1 + 3 + 1);
}

struct Damage {
  std::string name;                                       // the file damaged
  std::function<std::string(const std::string&)> damage;  // its new bytes from the old
  std::string what;                                       // words of the report
};

TEST_F(VerifyDecodes, EachKindDamagedBehindAMatchingManifestIsReported) {
  const auto half = [](const std::string& b) { return b.substr(0, b.size() / 2); };
  const auto flip_at = [](std::size_t at) {
    return [at](const std::string& b) {
      std::string c = b;
      c[at] = static_cast<char>(c[at] ^ 0x5a);
      return c;
    };
  };
  const std::vector<Damage> cases = {
      {"slice_00003.png", half, "PNG"},
      {"legacy/slice_00004_m0.bmp", half, "BMP header says"},
      // Bits per pixel (byte 28) from 1 to 8: the sizes still agree, the decoder refuses.
      {"legacy/slice_00005_m1.bmp",
       [](const std::string& b) {
         std::string c = b;
         c[28] = 8;
         return c;
       },
       "bits per pixel"},
      {"tiff/stack.tif", half, "tiff/stack.tif"},
      {"vdb/stack.vdb", half, "OpenVDB"},
      // A byte of the first PNG entry, after its 30-byte local header and name.
      {"gcvf/stack.gcvf", flip_at(30 + std::string("slice_0.png").size() + 100), "CRC-32"},
      {"gcvf/stack.gcvf", half, "gcvf/stack.gcvf"},
  };
  int index = 0;
  for (const Damage& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = copy(fmt::format("case{}", index++));
    replace_listed(dir, c.name, c.damage(read_bytes(dir / c.name)));
    expect_one_problem(verify_output(dir), c.name, c.what);
    fs::remove_all(dir);
  }
}

TEST_F(VerifyDecodes, EachKindDamagedBehindTheOldManifestFailsItsHash) {
  for (const std::string name :
       {"slice_00003.png", "legacy/slice_00004_m0.bmp", "tiff/stack.tif", "vdb/stack.vdb", "gcvf/stack.gcvf"}) {
    SCOPED_TRACE(name);
    const fs::path dir = copy("hash");
    std::string b = read_bytes(dir / name);
    b[b.size() / 2] = static_cast<char>(b[b.size() / 2] ^ 1);
    write_bytes(dir / name, b);
    expect_one_problem(verify_output(dir), name, "SHA-256");
    fs::remove_all(dir);
  }
}

// Well-formed files of another job: a taller object in the third of three materials, so
// more layers, more pages and images, and one grid more.
TEST_F(VerifyDecodes, StacksOfAnotherJobAreReported) {
  Scene tall = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {3, 1.5, 1.5}), 2, 3)}, 3);
  tall.source = "tall-scene";
  const Slicer slicer(tall, {});
  ASSERT_GT(slicer.layout().num_layers, 30);
  const fs::path other = fs::temp_directory_path() / fmt::format("trivox-verify-decode-{}-other", ::getpid());
  fs::remove_all(other);
  JobParams p;
  p.output_dir = other;
  p.threads = 2;
  p.formats = {"tiff", "vdb", "gcvf"};
  run_slice_job(slicer, p);
  const int layers = slicer.layout().num_layers;
  for (const auto& [name, what] : std::map<std::string, std::string>{
           {"tiff/stack.tif", fmt::format("{} pages, the job has 30 layers", layers)},
           {"gcvf/stack.gcvf", fmt::format("{} layer images, the job has 30 layers", layers)},
           {"vdb/stack.vdb", "3 grids, the job has 2 materials"}}) {
    SCOPED_TRACE(name);
    const fs::path dir = copy("with-other-stack");
    replace_listed(dir, name, read_bytes(other / name));
    expect_one_problem(verify_output(dir), name, what);
    fs::remove_all(dir);
  }
  fs::remove_all(other);
}

// A job whose only output is a stack (a lab that wants only the .gcvf) writes no file per
// layer: its one stack file holds every layer, and a complete job verifies. Its stack file
// must be listed: a manifest that lost the entry is reported.
TEST_F(VerifyDecodes, AJobWithOnlyAStackOutputVerifies) {
  const Slicer slicer(*scene_, {});
  for (const auto& [format, stack] : std::map<std::string, std::string>{
           {"gcvf", "gcvf/stack.gcvf"}, {"tiff", "tiff/stack.tif"}, {"vdb", "vdb/stack.vdb"}}) {
    SCOPED_TRACE(format);
    const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-verify-decode-{}-only-{}", ::getpid(), format);
    fs::remove_all(dir);
    JobParams p;
    p.output_dir = dir;
    p.threads = 2;
    p.formats = {format};
    run_slice_job(slicer, p);
    const VerifyReport r = verify_output(dir);
    EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
    EXPECT_EQ(r.files_checked, 2);  // the stack and materials.csv

    JobManifest m = read_manifest(dir / "manifest.json");
    m.files.erase(
        std::remove_if(m.files.begin(), m.files.end(), [&](const ManifestFile& f) { return f.name == stack; }),
        m.files.end());
    write_manifest(dir / "manifest.json", m);
    expect_one_problem(verify_output(dir), "manifest.json", fmt::format("no file of the '{}' output", format));
    fs::remove_all(dir);
  }
}

}  // namespace
}  // namespace trivox
