// `trivox probe`: evaluate-then-invert round trips on the bundled examples, an exact point of
// the rational annulus, several patches, and the documented handling of malformed lines.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "support/test_support.h"

namespace trivox::test {
namespace {

std::string model(const char* name) { return shell_quote(examples_dir() / "models" / name); }

std::string g17(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string line_of(const std::vector<double>& xs) {
  std::string s;
  for (double x : xs) {
    if (!s.empty()) s += ' ';
    s += g17(x);
  }
  return s + "\n";
}

std::vector<double> numbers(const nlohmann::json& array) { return array.get<std::vector<double>>(); }

// Evaluates a grid of parameters (interior, faces, edges and corners), feeds the printed
// positions back to the inversion and expects the parameters again, within 1e-9.
void expect_round_trip(const char* name, const std::vector<double>& ticks) {
  std::string params;
  std::vector<std::vector<double>> uvws;
  for (double w : ticks)
    for (double v : ticks)
      for (double u : ticks) {
        uvws.push_back({u, v, w});
        params += line_of(uvws.back());
      }
  const CliResult eval = run_cli("probe --eval --patch 0 " + model(name), params);
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  const auto evaluated = json_lines(eval.out);
  ASSERT_EQ(evaluated.size(), uvws.size());
  std::string positions;
  for (std::size_t i = 0; i < evaluated.size(); ++i) {
    ASSERT_EQ(evaluated[i].at("status"), "ok") << evaluated[i].dump();
    EXPECT_EQ(evaluated[i].at("line"), i + 1);
    EXPECT_EQ(numbers(evaluated[i].at("input")), uvws[i]);  // 17 digits: the input comes back exactly
    positions += line_of(numbers(evaluated[i].at("position")));
  }

  // The default tolerance (1e-8 mm) leaves parameter errors near 1e-9 on the column; a tighter
  // one makes the comparison exact to far below the bound.
  const CliResult inv = run_cli("probe --tolerance 1e-10 " + model(name), positions);
  ASSERT_EQ(inv.exit_code, 0) << inv.err;
  const auto inverted = json_lines(inv.out);
  ASSERT_EQ(inverted.size(), uvws.size());
  for (std::size_t i = 0; i < inverted.size(); ++i) {
    const nlohmann::json& r = inverted[i];
    ASSERT_EQ(r.at("status"), "unique") << r.dump();
    ASSERT_EQ(r.at("preimages").size(), 1u) << r.dump();
    const nlohmann::json& p = r["preimages"][0];
    EXPECT_EQ(p.at("patch"), 0);
    EXPECT_LE(p.at("residual").get<double>(), 1e-10);
    EXPECT_GT(p.at("det").get<double>(), 0.0);  // both examples are right-handed
    const auto uvw = numbers(p.at("uvw"));
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(uvw[d], uvws[i][d], 1e-9) << name << " line " << i + 1 << " direction " << d;
  }
}

TEST(CliProbe, EvalThenInvertRoundTripsOnTheTwistedColumn) {
  expect_round_trip("twisted_column.itd", {0.0, 0.4, 1.1, 1.7, 2.5, 3.0});
}

TEST(CliProbe, EvalThenInvertRoundTripsOnTheAnnulusSector) {
  expect_round_trip("annulus_sector.itd", {0.0, 0.2, 0.5, 0.9, 1.0});
}

// The sector is an exact quarter annulus (radii 20 and 30 mm, height 10 mm) whose angle
// parameter v = 1/2 lies exactly at 45 degrees, so (25 cos 45, 25 sin 45, 5) is (1/2, 1/2, 1/2).
TEST(CliProbe, InvertsAnExactPointOfTheRationalAnnulus) {
  const double c = 25.0 * std::numbers::sqrt2 / 2.0;
  const CliResult r = run_cli("probe " + model("annulus_sector.itd"), line_of({c, c, 5.0}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].at("status"), "unique");
  const auto uvw = numbers(lines[0]["preimages"][0]["uvw"]);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(uvw[d], 0.5, 1e-9);
}

TEST(CliProbe, PointOutsideHasNoPreimage) {
  const CliResult r = run_cli("probe " + model("twisted_column.itd"), "22 15 75\n-50 0 30\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 2u);
  for (const auto& l : lines) {
    EXPECT_EQ(l.at("status"), "none");
    EXPECT_TRUE(l.at("preimages").empty());
  }
}

TEST(CliProbe, EvalOutsideTheDomainIsAnAnswerNotAnError) {
  const CliResult r = run_cli("probe --eval --patch 0 " + model("annulus_sector.itd"), "1.5 0.5 0.5\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].at("status"), "outside");
  EXPECT_FALSE(lines[0].contains("position"));
}

TEST(CliProbe, SkipsBlankLinesAndCommentsAndNumbersLinesAsInTheInput) {
  const CliResult r =
      run_cli("probe --eval --patch 0 " + model("annulus_sector.itd"), "# header\n\n   \n0 0 0  # a corner\n1,1,1\r\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].at("line"), 4);
  EXPECT_EQ(numbers(lines[0].at("position")), (std::vector<double>{20, 0, 0}));
  EXPECT_EQ(lines[1].at("line"), 5);
  const auto p = numbers(lines[1].at("position"));
  EXPECT_NEAR(p[0], 0.0, 1e-12);
  EXPECT_NEAR(p[1], 30.0, 1e-12);
  EXPECT_NEAR(p[2], 10.0, 1e-12);
}

// Every malformed line gets an error line in place, the other lines are still answered, and
// the exit code is 3 with a message naming the first malformed line.
TEST(CliProbe, MalformedLinesGiveErrorLinesAndExit3) {
  const CliResult r = run_cli("probe " + model("twisted_column.itd"), "0 0 0\n1 2\nabc 1 2\n22 15 30\n1 2 3 4\n");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("<stdin>:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 malformed input lines"), std::string::npos) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].at("status"), "unique");
  for (int i : {1, 2, 4}) {
    EXPECT_EQ(lines[static_cast<std::size_t>(i)].at("line"), i + 1);
    EXPECT_EQ(lines[static_cast<std::size_t>(i)].at("status"), "error");
    EXPECT_FALSE(lines[static_cast<std::size_t>(i)].at("error").get<std::string>().empty());
  }
  EXPECT_NE(lines[2]["error"].get<std::string>().find("'abc'"), std::string::npos);
  EXPECT_EQ(lines[3].at("status"), "unique");
}

TEST(CliProbe, NonFiniteNumbersAreMalformed) {
  const CliResult r = run_cli("probe " + model("twisted_column.itd"), "nan 0 0\n0 inf 0\n1e999 0 0\n");
  EXPECT_EQ(r.exit_code, 3);
  for (const auto& l : json_lines(r.out)) EXPECT_EQ(l.at("status"), "error");
}

TEST(CliProbe, InvertingOnASurfacePatchIsAUsageError) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const std::string file = shell_quote(dir / "surfaces" / "teapot_irit.itd");
  EXPECT_EQ(run_cli("probe " + file, "0 0 0\n").exit_code, 2);
  EXPECT_EQ(run_cli("probe --patch 0 " + file, "0 0 0\n").exit_code, 2);
  // Evaluating a surface takes two parameters per line.
  const CliResult r = run_cli("probe --eval --patch 0 " + file, "0.5 0.5\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json_lines(r.out).at(0).at("position").size(), 3u);
}

// four_cubes_bspline.xml: four unit-square-based boxes; patches 0 and 1 share the face z = 0.5
// and all four meet along the edge x in [0, 1], y = z = 0.5.
TEST(CliProbe, ReportsPreimagesInEveryPatchAndCanBeLimitedToOne) {
  const auto dir = shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << shared_data_missing_message();
  const std::string file = shell_quote(dir / "volumes" / "gismo" / "four_cubes_bspline.xml");
  const CliResult r = run_cli("probe " + file, "0.5 0.25 0.25\n0.5 0.25 0.5\n0.5 0.5 0.5\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].at("status"), "unique");
  EXPECT_EQ(lines[1].at("status"), "multiple");
  ASSERT_EQ(lines[1].at("preimages").size(), 2u);
  EXPECT_EQ(lines[1]["preimages"][0]["patch"], 0);
  EXPECT_EQ(lines[1]["preimages"][1]["patch"], 1);
  EXPECT_EQ(lines[2].at("status"), "multiple");
  EXPECT_EQ(lines[2].at("preimages").size(), 4u);

  const CliResult one = run_cli("probe --patch 1 " + file, "0.5 0.25 0.5\n0.5 0.25 0.25\n");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const auto limited = json_lines(one.out);
  ASSERT_EQ(limited.size(), 2u);
  EXPECT_EQ(limited[0].at("status"), "unique");
  EXPECT_EQ(limited[0]["preimages"][0]["patch"], 1);
  EXPECT_EQ(limited[1].at("status"), "none");
}

}  // namespace
}  // namespace trivox::test
