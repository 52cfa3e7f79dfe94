// `trivox build`: a construction file becomes a model file with the same volume the library
// builds; a fold is an error that writes nothing, unless --allow-fold.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "trivox/io/model.h"
#include "trivox/scene/construction.h"

namespace trivox::test {
namespace {

const char* const kTube = R"({ "revolve": {
  "profile": { "orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
               "points": [[8, 0, 0], [10, 0, 0], [8, 0, 20], [10, 0, 20]] },
  "angle_deg": 270 } })";

// The top plate is the bottom one mirrored in x: the rulings cross at mid-height.
const char* const kFolded = R"({ "ruled": {
  "from": { "orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]] },
  "to": { "orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[10, 0, 4], [0, 0, 4], [10, 10, 4], [0, 10, 4]] } } })";

TEST(CliBuild, WritesTheConstructedVolume) {
  ScratchDir dir;
  write_text(dir.path() / "tube.json", kTube);
  const auto out = dir.path() / "tube.itd";
  const CliResult r =
      run_cli("build " + shell_quote(dir.path() / "tube.json") + " -o " + shell_quote(out) + " --name TUBE");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("revolve volume"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("jacobian"), std::string::npos) << r.out;
  const Model m = read_model(out);
  ASSERT_EQ(m.patches.size(), 1u);
  EXPECT_EQ(m.patches[0].name, "TUBE");
  const Constructed c = read_construction(dir.path() / "tube.json");
  const TensorSpline& a = m.patches[0].spline;
  const TensorSpline& b = c.volume.spline();
  ASSERT_EQ(a.points().size(), b.points().size());
  // IRIT stores rational points pre-multiplied by their weights: equal up to rounding.
  for (std::size_t i = 0; i < a.points().size(); ++i) EXPECT_NEAR(a.points()[i], b.points()[i], 1e-13 * 20);
  for (std::size_t i = 0; i < a.weights().size(); ++i) EXPECT_NEAR(a.weights()[i], b.weights()[i], 1e-15);
}

TEST(CliBuild, AFoldIsAnErrorUnlessAllowed) {
  ScratchDir dir;
  write_text(dir.path() / "fold.json", kFolded);
  const auto out = dir.path() / "fold.itd";
  const std::string args = "build " + shell_quote(dir.path() / "fold.json") + " -o " + shell_quote(out);
  const CliResult r = run_cli(args);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("folds over itself"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("w [0.625, 1]"), std::string::npos) << r.err;  // where it folds
  EXPECT_FALSE(std::filesystem::exists(out));
  const CliResult allowed = run_cli(args + " --allow-fold");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_NE(allowed.err.find("warning"), std::string::npos) << allowed.err;
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(CliBuild, BadFieldsNameTheirPointer) {
  ScratchDir dir;
  std::string spec = kTube;
  spec.replace(spec.find("270"), 3, "720");
  write_text(dir.path() / "bad.json", spec);
  const CliResult r =
      run_cli("build " + shell_quote(dir.path() / "bad.json") + " -o " + shell_quote(dir.path() / "x.itd"));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("/revolve/angle_deg"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace trivox::test
