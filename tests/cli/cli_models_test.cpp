// Model formats at the command line: `trivox build` writes the format the output's extension
// names (.itd, .xml, .g2) and refuses another; `info` and `probe` read GoTools .g2 like the
// other formats, `info` lists a reader's notes and says where a folded patch folds.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "support/test_support.h"
#include "trivox/io/model.h"
#include "trivox/scene/construction.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

const char* const kTube = R"({ "revolve": {
  "profile": { "orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
               "points": [[8, 0, 0], [10, 0, 0], [8, 0, 20], [10, 0, 20]] },
  "angle_deg": 360 } })";

std::string fmt_line(const std::vector<double>& xs) {
  std::string s;
  char buf[40];
  for (double x : xs) {
    std::snprintf(buf, sizeof buf, "%.17g", x);
    if (!s.empty()) s += ' ';
    s += buf;
  }
  return s + "\n";
}

std::string g2_model() { return shell_quote(fs::path(TRIVOX_TEST_DATA_DIR) / "models" / "quarter_annulus.g2"); }

TEST(CliModels, BuildWritesTheFormatTheExtensionNames) {
  ScratchDir dir;
  write_text(dir.path() / "tube.json", kTube);
  const Constructed c = read_construction(dir.path() / "tube.json");
  for (const char* name : {"tube.itd", "tube.xml", "tube.g2", "TUBE.G2"}) {
    SCOPED_TRACE(name);
    const fs::path out = dir.path() / name;
    const CliResult r = run_cli("build " + shell_quote(dir.path() / "tube.json") + " -o " + shell_quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Model m = read_model(out);
    ASSERT_EQ(m.patches.size(), 1u);
    const TensorSpline& a = m.patches[0].spline;
    const TensorSpline& b = c.volume.spline();
    EXPECT_EQ(a.all_knots(), b.all_knots());
    ASSERT_EQ(a.points().size(), b.points().size());
    // G+Smo keeps coordinates and weights apart (exact); IRIT and GoTools store w * x.
    const bool exact = std::string(name) == "tube.xml";
    for (std::size_t i = 0; i < a.points().size(); ++i)
      if (exact)
        EXPECT_EQ(a.points()[i], b.points()[i]) << i;
      else
        EXPECT_NEAR(a.points()[i], b.points()[i], 1e-13 * 20) << i;
    EXPECT_TRUE(std::equal(a.weights().begin(), a.weights().end(), b.weights().begin(), b.weights().end()));
  }
  // The full turn's faces w = 0 and w = 1 (the angle) coincide: G+Smo's topology glues them,
  // the normal direction running on from one to the other.
  const std::string xml = read_text(dir.path() / "tube.xml");
  EXPECT_NE(xml.find("<interfaces>\n0 5 0 6 0 1 2 1 1 1\n  </interfaces>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<boundary>\n0 1\n0 2\n0 3\n0 4\n  </boundary>"), std::string::npos) << xml;

  const CliResult bad =
      run_cli("build " + shell_quote(dir.path() / "tube.json") + " -o " + shell_quote(dir.path() / "tube.stl"));
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find(".itd (IRIT), .xml (G+Smo) or .g2 (GoTools)"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir.path() / "tube.stl"));
}

TEST(CliModels, InfoReadsG2WithItsNotes) {
  const CliResult r = run_cli("info " + g2_model());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("2 patches (1 trivariate, 1 surface)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("note: line 14: skipped a Plane (class 250, lines 14 to 16)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("patch 1 \"SplineVolume #2\" (id 1, line 18)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("orders 2 x 3 x 2"), std::string::npos) << r.out;

  const CliResult j = run_cli("info --json " + g2_model());
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const nlohmann::json doc = nlohmann::json::parse(j.out);
  ASSERT_EQ(doc["notes"].size(), 1u);
  EXPECT_EQ(doc["notes"][0]["line"], 14);
  EXPECT_EQ(doc["patches"][1]["rational"], true);
}

// The volume is an exact quarter annulus, radii 1 to 2, height 3 (w in [0, 3]): the point at
// radius 1.5, 45 degrees, height 1.5 is (u, v, w) = (1/2, 1/2, 1.5).
TEST(CliModels, ProbeInvertsInAG2Volume) {
  const double c = 1.5 * std::sqrt(0.5);
  const CliResult r = run_cli("probe " + g2_model(), fmt_line({c, c, 1.5}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json line = nlohmann::json::parse(r.out);
  ASSERT_EQ(line.at("status"), "unique") << r.out;
  EXPECT_EQ(line["preimages"][0]["patch"], 1);
  EXPECT_NEAR(line["preimages"][0]["uvw"][0].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(line["preimages"][0]["uvw"][1].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(line["preimages"][0]["uvw"][2].get<double>(), 1.5, 1e-9);
}

TEST(CliModels, InfoSaysWhereAFoldedPatchFolds) {
  const fs::path dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const std::string file = shell_quote(dir / "volumes/gismo/tensorBSpline.xml");
  const CliResult r = run_cli("info " + file);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("jacobian folded"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("folds: det J > 0 at 26 samples in u [0.166667, 0.833333]  v [0, 1]  w [0.666667, 1]"),
            std::string::npos)
      << r.out;
  const CliResult j = run_cli("info --json " + file);
  const nlohmann::json doc = nlohmann::json::parse(j.out);
  const nlohmann::json& folds = doc["patches"][0]["jacobian"]["folds"];
  ASSERT_EQ(folds.size(), 1u);
  EXPECT_EQ(folds[0]["samples"], 26);
  EXPECT_NEAR(folds[0]["w"][0].get<double>(), 2.0 / 3.0, 1e-15);
  EXPECT_EQ(folds[0]["w"][1], 1.0);
}

// A point on camembert.xml's axis (the face u = 0 collapses onto it) answers degenerate with
// one preimage, not a list of near-duplicates along the collapsed edge.
TEST(CliModels, ProbeAnswersDegenerateWithOnePreimageOnACollapsedEdge) {
  const fs::path dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const CliResult r = run_cli("probe " + shell_quote(dir / "volumes/gismo/camembert.xml"), "0 0 0.5\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json line = nlohmann::json::parse(r.out);
  EXPECT_EQ(line.at("status"), "degenerate") << r.out;
  EXPECT_EQ(line.at("preimages").size(), 1u) << r.out;
}

}  // namespace
}  // namespace trivox::test
