// `trivox probe` round trips on every real volume file in ../shared/data/volumes: parameters
// evaluated by the program, inverted by the program, and the original parameters found among
// the preimages it reports (the global solver lists every preimage, also on folded patches).
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox::test {
namespace {

std::string g17(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

TEST(CliSharedProbe, RoundTripsOnEveryVolumeFile) {
  const std::filesystem::path data = shared_data_dir();
  if (data.empty()) GTEST_SKIP() << shared_data_missing_message();
  int files = 0, patches = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(data / "volumes")) {
    if (!entry.is_regular_file()) continue;
    Model model;
    try {
      model = read_model(entry.path());
    } catch (const UnsupportedError&) {
      continue;  // thbcube.xml: hierarchical splines, reported as unsupported elsewhere
    }
    ++files;
    for (int index : model.volume_indices()) {
      const TensorSpline& s = model.patches[static_cast<std::size_t>(index)].spline;
      if (s.point_dim() != 3) continue;  // scalar fields (IRIT E1) have no positions to invert
      SCOPED_TRACE(entry.path().filename().string() + " patch " + std::to_string(index));
      ++patches;
      // Interior parameters: away from faces that may collapse, where preimages are a continuum.
      std::vector<std::array<double, 3>> params;
      std::string input;
      for (double a : {0.23, 0.5, 0.81})
        for (double b : {0.31, 0.62})
          for (double c : {0.27, 0.74}) {
            const std::array<double, 3> t{s.lo(0) + a * (s.hi(0) - s.lo(0)), s.lo(1) + b * (s.hi(1) - s.lo(1)),
                                          s.lo(2) + c * (s.hi(2) - s.lo(2))};
            params.push_back(t);
            input += g17(t[0]) + " " + g17(t[1]) + " " + g17(t[2]) + "\n";
          }
      const std::string file = shell_quote(entry.path());
      const CliResult eval = run_cli("probe --eval --patch " + std::to_string(index) + " " + file, input);
      ASSERT_EQ(eval.exit_code, 0) << eval.err;
      const auto evaluated = json_lines(eval.out);
      ASSERT_EQ(evaluated.size(), params.size());
      std::string positions;
      for (const auto& e : evaluated) {
        const auto p = e.at("position").get<std::vector<double>>();
        positions += g17(p[0]) + " " + g17(p[1]) + " " + g17(p[2]) + "\n";
      }
      const CliResult inv = run_cli("probe --patch " + std::to_string(index) + " " + file, positions);
      ASSERT_EQ(inv.exit_code, 0) << inv.err;
      const auto inverted = json_lines(inv.out);
      ASSERT_EQ(inverted.size(), params.size());
      for (std::size_t i = 0; i < params.size(); ++i) {
        const nlohmann::json& r = inverted[i];
        ASSERT_NE(r.at("status"), "none") << r.dump();
        bool found = false;
        for (const auto& p : r.at("preimages")) {
          EXPECT_LE(p.at("residual").get<double>(), 1e-8) << r.dump();
          const auto uvw = p.at("uvw").get<std::vector<double>>();
          bool same = true;
          for (int d = 0; d < 3; ++d)
            same = same && std::abs(uvw[static_cast<std::size_t>(d)] - params[i][static_cast<std::size_t>(d)]) <=
                               1e-6 * (s.hi(d) - s.lo(d));
          found = found || same;
        }
        EXPECT_TRUE(found) << "the evaluated parameters are not among the preimages: " << r.dump();
      }
    }
  }
  EXPECT_GE(files, 40);
  EXPECT_GE(patches, 100);
}

}  // namespace
}  // namespace trivox::test
