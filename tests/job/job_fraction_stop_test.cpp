// A job that meets a fraction sum above 1 stops at once, naming the cell, the layer, the
// position and the parameters; it resumes after a correction of the scene only if the
// correction cannot change the layers it completed.
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "job/job_fixtures.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/job/job_folder.h"
#include "trivox/job/manifest.h"
#include "trivox/material/material_function.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-fraction-stop-{}-{}", ::getpid(), name);
  fs::remove_all(dir);
  return dir;
}

// Two stacked plates 3 x 2 mm, each its own cell: "low" (z 0 to 0.31) and "high" (z 0.31 to
// 0.6; no layer's plane is at their common face), with the materials and fraction policy
// given.
std::string scene_text(const std::string& low, const std::string& high,
                       const std::string& policy = R"j({"policy": "error"})j") {
  const auto plate = [](double z0, double z1) {
    return fmt::format(R"j({{"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
      "points": [[0, 0, {0}], [3, 0, {0}], [0, 2, {0}], [3, 2, {0}], [0, 0, {1}], [3, 0, {1}], [0, 2, {1}], [3, 2, {1}]]}})j",
                       z0, z1);
  };
  return fmt::format(R"j({{"units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
    "fraction_sums": {},
    "cells": [{{"name": "low", "geometry": {}, "material": {{"kind": "expression", "fractions": {}}}}},
              {{"name": "high", "geometry": {}, "material": {{"kind": "expression", "fractions": {}}}}}]}})j",
                     policy, plate(0, 0.31), low, plate(0.31, 0.6), high);
}

const std::string kFine = R"j({"VeroCyan": "1 - u", "VeroMagenta": "u"})j";
// Above 1 where w > 0.5: in the upper half of the plate.
const std::string kBadTop = R"j({"VeroCyan": "1 - u + (w > 0.5 ? 0.5 : 0)", "VeroMagenta": "u"})j";

JobParams params_for(const fs::path& dir) {
  JobParams p;
  p.output_dir = dir;
  p.threads = 1;  // layers in order: the job stops at its first bad layer
  p.manifest_interval_seconds = 0;
  return p;
}

// Slices `text` into `dir` and returns the FractionError it stops with.
FractionError stopped(const std::string& text, const fs::path& dir, bool resume = false) {
  const Scene scene = parse_scene(text, "scene.json");
  const Slicer slicer(scene, {});
  JobParams p = params_for(dir);
  p.resume = resume;
  try {
    run_slice_job(slicer, p);
  } catch (const FractionError& e) {
    return e;
  }
  ADD_FAILURE() << "the job did not stop";
  throw std::logic_error("no error");
}

TEST(JobFractionStop, StopsAtOnceNamingCellLayerPositionAndParameters) {
  const fs::path dir = fresh_dir("stop");
  const FractionError e = stopped(scene_text(kFine, kBadTop), dir);
  const Scene scene = parse_scene(scene_text(kFine, kBadTop), "scene.json");
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  // The first layer whose plane lies above the middle of the high plate.
  int bad = 0;
  while (L.z_of_layer(bad) <= 0.31 + 0.5 * 0.29) ++bad;
  EXPECT_EQ(e.layer(), bad + 1);
  EXPECT_EQ(e.cell(), "high");
  EXPECT_EQ(e.where(), "/cells/1/material");
  ASSERT_TRUE(e.has_position());
  EXPECT_NEAR(e.xyz().z, L.z_of_layer(bad), 1e-9);
  const std::string what = e.what();
  for (const std::string& part :
       {fmt::format("layer {} (z = {:.6g} mm)", bad + 1, L.z_of_layer(bad)), std::string("cell 'high'"),
        std::string("the fractions sum to 1.5"),
        fmt::format("(u,v,w) = ({:.6g}, {:.6g}, {:.6g})", e.uvw().x, e.uvw().y, e.uvw().z),
        fmt::format("(x,y,z) = ({:.6g}, {:.6g}, {:.6g}) mm", e.xyz().x, e.xyz().y, e.xyz().z)})
    EXPECT_NE(what.find(part), std::string::npos) << part << " in " << what;
  // At once: every layer below the bad one is complete and recorded, none above it.
  const JobManifest m = read_manifest(dir / "manifest.json");
  EXPECT_EQ(m.status, JobStatus::kFailed);
  EXPECT_NE(m.message.find("cell 'high'"), std::string::npos) << m.message;
  std::set<int> layers;
  for (const ManifestFile& f : m.files) layers.insert(f.layer);
  EXPECT_EQ(static_cast<int>(layers.size()), bad);
  EXPECT_EQ(*layers.rbegin(), bad);
  fs::remove_all(dir);
}

// The usual correction, "normalise": it changes no sample a completed layer met, so the
// layers are kept and the result is that of a fresh run with the corrected scene.
TEST(JobFractionStop, ResumesAfterACorrectionThatCannotChangeTheCompletedLayers) {
  const fs::path dir = fresh_dir("normalise");
  (void)stopped(scene_text(kFine, kBadTop), dir);
  const Scene fixed = parse_scene(scene_text(kFine, kBadTop, R"j({"policy": "normalise"})j"), "scene.json");
  const Slicer slicer(fixed, {});
  JobParams p = params_for(dir);
  p.resume = true;
  p.threads = 2;
  const JobStats st = run_slice_job(slicer, p);
  EXPECT_GT(st.layers_kept, 0);
  EXPECT_TRUE(verify_output(dir).ok());
  const fs::path fresh = fresh_dir("normalise-fresh");
  run_slice_job(slicer, params_for(fresh));
  auto a = test::folder_bytes(dir), b = test::folder_bytes(fresh);
  a.erase("stats.json");
  b.erase("stats.json");
  EXPECT_EQ(a, b);
  fs::remove_all(dir);
  fs::remove_all(fresh);

  // Correcting the cell that failed, which reaches no completed layer (it fails in its first
  // layer): resumed too.
  const fs::path dir2 = fresh_dir("high");
  (void)stopped(scene_text(kFine, R"j({"VeroCyan": "1 - u + 0.5", "VeroMagenta": "u"})j"), dir2);
  const Scene corrected = parse_scene(scene_text(kFine, kFine), "scene.json");
  const Slicer slicer2(corrected, {});
  JobParams p2 = params_for(dir2);
  p2.resume = true;
  EXPECT_GT(run_slice_job(slicer2, p2).layers_kept, 0);
  EXPECT_TRUE(verify_output(dir2).ok());
  fs::remove_all(dir2);
}

// A correction that may change completed layers is refused, naming the cell and the layers;
// so is a stricter policy, which might refuse what they hold.
TEST(JobFractionStop, RefusesACorrectionThatMayChangeTheCompletedLayers) {
  // The low plate fails in its upper half, after its lower layers completed.
  const std::string bad_low = R"j({"VeroCyan": "1 - u + (w > 0.5 ? 0.5 : 0)", "VeroMagenta": "u"})j";
  const struct {
    std::string text, what, layers;
  } cases[] = {
      {scene_text(R"j({"VeroCyan": "1 - u", "VeroMagenta": "u + 0"})j", kFine), "cell 'low' has changed", "layers 1-"},
      {scene_text(bad_low, kFine, R"j({"policy": "error", "tolerance": 0})j"), "the fraction policy was", ""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const fs::path dir = fresh_dir("refuse");
    (void)stopped(scene_text(bad_low, kFine), dir);
    const Scene changed = parse_scene(c.text, "scene.json");
    const Slicer slicer(changed, {});
    JobParams p = params_for(dir);
    p.resume = true;
    try {
      run_slice_job(slicer, p);
      ADD_FAILURE() << "resumed over layers the correction may change";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.what), std::string::npos) << what;
      EXPECT_NE(what.find(c.layers), std::string::npos) << what;
    }
    fs::remove_all(dir);
  }
}

}  // namespace
}  // namespace trivox
