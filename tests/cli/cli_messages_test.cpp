// Messages a person can act on, whatever the input (issue 16, section 1): a duplicate colour
// names the scene, the field and both materials; a directory given as a model says so; range
// errors print numbers in %g style, never the largest double's 309 digits; a name of a million
// characters is echoed cut, with its length; -j is bounded, the summary reports the threads
// the job ran on, and oneTBB prints no warning of its own.
#include <regex>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"
#include "cli_small_scene.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// The longest run of digits in `text`.
std::size_t longest_digit_run(const std::string& text) {
  std::size_t longest = 0, run = 0;
  for (char c : text) {
    run = std::isdigit(static_cast<unsigned char>(c)) ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  return longest;
}

TEST(CliMessages, ADuplicateColourNamesTheSceneTheFieldAndBothMaterials) {
  ScratchDir dir;
  write_text(dir.path() / "dup.json", R"({"version": 1, "units": "mm", "printer": "j750-hm",
 "materials": [{"name": "VeroCyan"}, {"name": "copy", "rgba": [0, 160, 227, 200]}],
 "cells": [{"name": "box", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0], [0, 0, 4], [4, 0, 4], [0, 4, 4], [4, 4, 4]]},
   "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}]})");
  const CliResult r =
      run_cli(fmt::format("slice {} -o {} -q", shell_quote(dir.path() / "dup.json"), shell_quote(dir.path() / "out")));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("dup.json: /materials/1: material 'copy' has the image colour #00A0E3 of material 'VeroCyan' "
                       "(/materials/0)"),
            std::string::npos)
      << r.err;
}

TEST(CliMessages, ADirectoryGivenAsAModelIsCalledADirectory) {
  ScratchDir dir;
  fs::create_directories(dir.path() / "model.itd");
  const CliResult info = run_cli("info " + shell_quote(dir.path() / "model.itd"));
  EXPECT_EQ(info.exit_code, 4) << info.err;
  EXPECT_NE(info.err.find("it is a directory"), std::string::npos) << info.err;
  write_text(dir.path() / "scene.json", R"({"version": 1, "units": "mm", "printer": "j750-hm",
 "materials": [{"name": "VeroCyan"}],
 "cells": [{"name": "c", "geometry": {"file": "model.itd"}, "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}]})");
  const CliResult scene = run_cli("validate " + shell_quote(dir.path() / "scene.json"));
  EXPECT_EQ(scene.exit_code, 3) << scene.err;
  EXPECT_NE(scene.err.find("/cells/0/geometry/file: cannot read the model file \"model.itd\": "), std::string::npos)
      << scene.err;
  EXPECT_NE(scene.err.find("model.itd is a directory, not a file"), std::string::npos) << scene.err;
  EXPECT_EQ(scene.err.find("there is no file"), std::string::npos) << scene.err;
}

TEST(CliMessages, RangeErrorsPrintNumbersAsAPersonReadsThem) {
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene());
  const std::string slice =
      fmt::format("slice {} -o {} -q ", shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out"));
  for (const char* option : {"--residual-tolerance 1e400", "--residual-tolerance -1e308", "--outline-tolerance 0",
                             "--memory-limit -5", "--manifest-interval 1e308"}) {
    const CliResult r = run_cli(slice + option);
    EXPECT_EQ(r.exit_code, 2) << option << ": " << r.err;
    EXPECT_LE(longest_digit_run(r.err), 17u) << option << ": " << r.err;
  }
  EXPECT_NE(run_cli(slice + "--manifest-interval 1e308").err.find("is not a number from 0 to 86400"),
            std::string::npos);
  EXPECT_NE(run_cli(slice + "--residual-tolerance 1e400").err.find("Value '1e400' is not a finite number > 0"),
            std::string::npos);
  // A layer 1e-300 mm thick: the warning's percentage in %g.
  write_text(dir.path() / "thin.json",
             small_box_scene({"VeroCyan"}, 4, R"({"base": "j750-hm", "layer_thickness_mm": 1e-300})"));
  const CliResult thin = run_cli("validate " + shell_quote(dir.path() / "thin.json"));
  EXPECT_EQ(thin.exit_code, 3) << thin.err;
  EXPECT_NE(thin.err.find("the part comes out 1.4e+300 % taller"), std::string::npos) << thin.err;
  EXPECT_LE(longest_digit_run(thin.err), 17u) << thin.err;
}

TEST(CliMessages, AMillionCharacterNameIsEchoedCutWithItsLength) {
  ScratchDir dir;
  const std::string name(1000000, 'y');
  write_text(dir.path() / "long.json", R"({"version": 1, "units": "mm", "printer": "j750-hm",
 "materials": [{"name": "VeroCyan"}, {"name": ")" +
                                           name + R"("}],
 "cells": [{"name": "box", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
   "points": [[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0], [0, 0, 4], [4, 0, 4], [0, 4, 4], [4, 4, 4]]},
   "material": {"kind": "constant", "fractions": {")" +
                                           name + R"(": 1}}}]})");
  const CliResult r = run_cli("validate " + shell_quote(dir.path() / "long.json"));
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_LT(r.err.size(), 2000u) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find(std::string(80, 'y') + "\"... (1000000 characters) is not a library material"),
            std::string::npos)
      << r.err.substr(0, 300);
}

TEST(CliMessages, ThreadsAreBoundedAndTheSummaryReportsThoseTheJobRanOn) {
  ScratchDir dir;
  write_text(dir.path() / "box.json", small_box_scene());
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int most = std::min(1024, 4 * hardware);
  const std::string slice = fmt::format("slice {} -o {} --layers 1:2 --min-layers 0 -q ",
                                        shell_quote(dir.path() / "box.json"), shell_quote(dir.path() / "out"));
  for (const std::string& j : {std::to_string(most + 1), std::string("100000"), std::string("1.5")}) {
    const CliResult r = run_cli(slice + "-j " + j);
    EXPECT_EQ(r.exit_code, 2) << j << ": " << r.err;
    EXPECT_NE(r.err.find(fmt::format("is no thread count: 0 (every core) to {} (4 per hardware thread", most)),
              std::string::npos)
        << r.err;
  }
  // More threads than cores: run as asked, without oneTBB's "TBB Warning" on standard error.
  const CliResult r = run_cli(slice + "-j " + std::to_string(most));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(fmt::format("with {} threads", most)), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
}

}  // namespace
}  // namespace trivox::test
