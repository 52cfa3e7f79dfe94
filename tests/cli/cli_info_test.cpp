// `trivox info`: the text and JSON descriptions of the bundled examples, and every real
// volume file of ../shared/data read end to end.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "support/test_support.h"

namespace trivox::test {
namespace {

std::string model(const char* name) { return shell_quote(examples_dir() / "models" / name); }

TEST(CliInfo, TextNamesThePatchAndItsOrientation) {
  const CliResult r = run_cli("info " + model("twisted_column.itd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("1 patch (1 trivariate)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"TWISTED_COLUMN\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("polynomial (B-spline)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("orders 4 x 4 x 4, control points 6 x 6 x 6 = 216"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("jacobian right-handed"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;

  const CliResult a = run_cli("info " + model("annulus_sector.itd"));
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.out.find("\"ANNULUS_SECTOR\""), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("rational (NURBS)"), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("jacobian right-handed"), std::string::npos) << a.out;
}

TEST(CliInfo, JsonHasEveryField) {
  const CliResult r = run_cli("info --json " + model("twisted_column.itd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  EXPECT_NE(doc.at("source").get<std::string>().find("twisted_column.itd"), std::string::npos);
  ASSERT_EQ(doc.at("patches").size(), 1u);
  const nlohmann::json& p = doc["patches"][0];
  EXPECT_EQ(p.at("index"), 0);
  EXPECT_EQ(p.at("name"), "TWISTED_COLUMN");
  EXPECT_GT(p.at("line").get<int>(), 0);
  EXPECT_EQ(p.at("kind"), "trivariate");
  EXPECT_EQ(p.at("param_dim"), 3);
  EXPECT_EQ(p.at("point_dim"), 3);
  EXPECT_EQ(p.at("rational"), false);
  EXPECT_EQ(p.at("orders"), nlohmann::json({4, 4, 4}));
  EXPECT_EQ(p.at("control_points"), nlohmann::json({6, 6, 6}));
  EXPECT_EQ(p.at("total_control_points"), 216);
  EXPECT_EQ(p.at("periodic"), nlohmann::json({false, false, false}));
  EXPECT_EQ(p.at("domain"), nlohmann::json({{0.0, 3.0}, {0.0, 3.0}, {0.0, 3.0}}));
  ASSERT_EQ(p.at("knots").size(), 3u);
  EXPECT_EQ(p["knots"][0], nlohmann::json({0, 0, 0, 0, 1, 2, 3, 3, 3, 3}));
  // The column stands on z = 0 and is 60 mm tall.
  EXPECT_EQ(p.at("bounds").at("lo").size(), 3u);
  EXPECT_DOUBLE_EQ(p["bounds"]["lo"][2].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(p["bounds"]["hi"][2].get<double>(), 60.0);
  const nlohmann::json& j = p.at("jacobian");
  EXPECT_EQ(j.at("class"), "right-handed");
  EXPECT_EQ(j.at("samples"), 343);
  EXPECT_EQ(j.at("positive"), 343);
  EXPECT_EQ(j.at("negative"), 0);
  EXPECT_EQ(j.at("zero"), 0);
  EXPECT_GT(j.at("min_det").get<double>(), 0.0);
  EXPECT_GE(j.at("max_det").get<double>(), j.at("min_det").get<double>());
}

TEST(CliInfo, JsonOfTheExactAnnulusSector) {
  const CliResult r = run_cli("info --json " + model("annulus_sector.itd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json p = nlohmann::json::parse(r.out).at("patches").at(0);
  EXPECT_EQ(p.at("rational"), true);
  EXPECT_EQ(p.at("orders"), nlohmann::json({2, 3, 2}));
  const double lo[3] = {0, 0, 0}, hi[3] = {30, 30, 10};
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(p["bounds"]["lo"][c].get<double>(), lo[c], 1e-12);
    EXPECT_NEAR(p["bounds"]["hi"][c].get<double>(), hi[c], 1e-12);
  }
  EXPECT_EQ(p.at("jacobian").at("class"), "right-handed");
}

TEST(CliInfo, JacobianSamplesOption) {
  const CliResult r = run_cli("info --json --jacobian-samples 3 " + model("annulus_sector.itd"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["patches"][0]["jacobian"]["samples"], 27);
  EXPECT_EQ(run_cli("info --jacobian-samples 1 " + model("annulus_sector.itd")).exit_code, 2);
}

TEST(CliInfo, ListsSurfacesAndCurvesWithoutJacobian) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const std::string file = shell_quote(dir / "volumes" / "irit" / "fltrtest.itd");
  const CliResult text = run_cli("info " + file);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("(1 trivariate, 5 surfaces, 1 curve)"), std::string::npos) << text.out;

  const CliResult r = run_cli("info --json " + file);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  for (const nlohmann::json& p : doc.at("patches")) {
    if (p.at("kind") == "trivariate")
      EXPECT_EQ(p.at("jacobian").at("class"), "left-handed");
    else
      EXPECT_TRUE(p.at("jacobian").is_null()) << p.dump();
  }
}

std::vector<std::filesystem::path> shared_volume_files(const std::filesystem::path& data) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(data / "volumes"))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(CliInfo, ReadsEverySharedVolumeFileButTheHierarchicalOne) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const auto files = shared_volume_files(dir);
  ASSERT_GE(files.size(), 40u);
  for (const auto& f : files) {
    const CliResult r = run_cli("info " + shell_quote(f));
    if (f.filename() == "thbcube.xml") {
      EXPECT_EQ(r.exit_code, 3) << f;
      EXPECT_NE(r.err.find("unsupported"), std::string::npos) << r.err;
    } else {
      EXPECT_EQ(r.exit_code, 0) << f << ": " << r.err;
    }
  }
}

// PROVENANCE.tsv counts, per file, the patches whose sampled Jacobian determinant is
// positive / negative / touches zero or changes sign (7x7x7 samples, like `info`'s default).
TEST(CliInfo, JacobianClassesMatchProvenance) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  std::ifstream tsv(dir / "PROVENANCE.tsv");
  std::string line;
  std::getline(tsv, line);  // header
  int compared = 0;
  while (std::getline(tsv, line)) {
    std::vector<std::string> cols;
    std::istringstream fields(line);
    for (std::string c; std::getline(fields, c, '\t');) cols.push_back(c);
    ASSERT_GE(cols.size(), 8u) << line;
    if (cols[0].rfind("volumes/", 0) != 0 || cols[7].empty()) continue;
    const CliResult r = run_cli("info --json " + shell_quote(dir / cols[0]));
    ASSERT_EQ(r.exit_code, 0) << cols[0] << ": " << r.err;
    int pos = 0, neg = 0, other = 0;
    bool all_geometry = true;
    const nlohmann::json doc = nlohmann::json::parse(r.out);
    for (const nlohmann::json& p : doc.at("patches")) {
      if (p.at("kind") != "trivariate") continue;  // the provenance counts trivariates only
      if (p.at("jacobian").is_null()) {            // a scalar field (E1): no Jacobian to classify
        EXPECT_NE(p.at("point_dim"), 3) << cols[0];
        all_geometry = false;
        continue;
      }
      const std::string c = p["jacobian"]["class"];
      if (c == "right-handed")
        ++pos;
      else if (c == "left-handed")
        ++neg;
      else
        ++other;
    }
    if (!all_geometry) continue;
    EXPECT_EQ(std::to_string(pos) + "/" + std::to_string(neg) + "/" + std::to_string(other), cols[7]) << cols[0];
    ++compared;
  }
  EXPECT_GE(compared, 40);
}

}  // namespace
}  // namespace trivox::test
