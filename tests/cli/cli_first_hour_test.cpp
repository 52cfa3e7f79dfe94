// What a new user does first: `trivox init` writes a scene that slices as is, verify accepts
// a job whose only output is the GrabCAD package, and nearly equal colours are warned about.
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"
#include "trivox/scene/scene.h"
#include "trivox/scene/starter_scene.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

// The one end-to-end test of `init`: the scene it writes reads, validates and slices whole,
// its output verifies, and the printed extent is the box's within a voxel.
TEST(CliFirstHour, InitWritesASceneThatSlicesAsIs) {
  ScratchDir dir;
  const fs::path scene = dir.path() / "bar.json";
  const CliResult init = run_cli("init " + shell_quote(scene));
  ASSERT_EQ(init.exit_code, 0) << init.err;
  EXPECT_NE(init.out.find("wrote "), std::string::npos) << init.out;
  EXPECT_NE(init.out.find("trivox slice"), std::string::npos) << init.out;
  // Self-describing: the description names every part of the scene.
  const nlohmann::json j = nlohmann::json::parse(read_text(scene));
  const std::string description = j.at("description").get<std::string>();
  for (const char* part : {"printer", "materials", "fraction_sums", "dithering", "cells", "u, v and w"})
    EXPECT_NE(description.find(part), std::string::npos) << part;
  for (const auto& m : j.at("materials")) EXPECT_TRUE(m.contains("description"));

  const CliResult validate = run_cli("validate " + shell_quote(scene) + " --samples 1");
  ASSERT_EQ(validate.exit_code, 0) << validate.err << validate.out;
  const fs::path out = dir.path() / "out";
  const CliResult slice = run_cli("slice " + shell_quote(scene) + " -o " + shell_quote(out) + " -q");
  ASSERT_EQ(slice.exit_code, 0) << slice.err;
  const std::size_t at = slice.out.find("printed extent: ");
  ASSERT_NE(at, std::string::npos) << slice.out;
  double x = 0, y = 0, z = 0;
  ASSERT_EQ(std::sscanf(slice.out.c_str() + at, "printed extent: %lf x %lf x %lf mm", &x, &y, &z), 3) << slice.out;
  EXPECT_NEAR(x, 20, 25.4 / 600);  // within a voxel: 600 x 300 dpi, 0.027 mm layers
  EXPECT_NEAR(y, 10, 25.4 / 300);
  EXPECT_NEAR(z, 5, 0.027);
  EXPECT_NE(slice.out.find("model: 20.00 x 10.00 x 5.00 mm"), std::string::npos) << slice.out;
  const CliResult verify = run_cli("verify " + shell_quote(out));
  EXPECT_EQ(verify.exit_code, 0) << verify.out;

  // Another printer and materials; an existing file is kept unless --force.
  const CliResult again = run_cli("init " + shell_quote(scene) + " --printer j750-hs --materials VeroYellow,VeroBlack");
  EXPECT_EQ(again.exit_code, 4) << again.err;
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
  const CliResult forced =
      run_cli("init " + shell_quote(scene) + " --printer J750-HS --materials veroyellow,vero-black --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  const Scene s = read_scene(scene);
  EXPECT_EQ(s.printer.name, "j750-hs");
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "VeroYellow");
  EXPECT_EQ(s.materials[1].name, "VeroBlack");
}

TEST(CliFirstHour, InitRefusesWhatItCannotWrite) {
  ScratchDir dir;
  const std::string scene = shell_quote(dir.path() / "x.json");
  for (const std::string& args : {std::string("--materials VeroCyan"), std::string("--materials VeroCyan,NoSuch"),
                                  std::string("--materials VeroCyan,vero_cyan"), std::string("--printer j999")}) {
    SCOPED_TRACE(args);
    const CliResult r = run_cli("init " + scene + " " + args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "x.json"));
  }
}

// The starter scene in the library: valid for every printer and any pair of library
// materials, in every size.
TEST(CliFirstHour, StarterScenesRead) {
  for (const char* printer : {"j750-hq", "j850-hm", "j750-hs", "j750-paper"})
    for (const std::vector<std::string>& materials :
         {std::vector<std::string>{"VeroCyan", "VeroMagenta"}, {"VeroClear", "Agilus30Black"}}) {
      StarterSceneParams p;
      p.printer = printer;
      p.materials = materials;
      p.size_mm = {0.1, 123.5, 1e-2};
      const Scene s = parse_scene(starter_scene_text(p), "starter.json");
      EXPECT_EQ(s.cells.size(), 1u);
      EXPECT_DOUBLE_EQ(s.bounds().size().y, 123.5);
    }
}

// A lab that only wants the .gcvf can verify it.
TEST(CliFirstHour, VerifyAcceptsAJobWithOnlyTheGrabCadPackage) {
  ScratchDir dir;
  const fs::path scene = dir.path() / "bar.json";
  ASSERT_EQ(run_cli("init " + shell_quote(scene)).exit_code, 0);
  const fs::path out = dir.path() / "out";
  const CliResult slice =
      run_cli("slice " + shell_quote(scene) + " -o " + shell_quote(out) + " -q --layers 1:4 --format gcvf");
  ASSERT_EQ(slice.exit_code, 0) << slice.err;
  const CliResult verify = run_cli("verify " + shell_quote(out));
  EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
  EXPECT_NE(verify.out.find("ok: 30 layers, 2 files"), std::string::npos) << verify.out;
}

// VeroWhite and Agilus30White: accepted, and warned about where a person looks.
TEST(CliFirstHour, NearlyEqualColoursAreWarnedAbout) {
  ScratchDir dir;
  const fs::path scene = dir.path() / "whites.json";
  const CliResult init = run_cli("init " + shell_quote(scene) + " --materials VeroWhite,Agilus30White");
  ASSERT_EQ(init.exit_code, 0) << init.err;
  EXPECT_NE(init.out.find("nearly the same colour"), std::string::npos) << init.out;
  const CliResult validate = run_cli("validate " + shell_quote(scene) + " --samples 0");
  EXPECT_EQ(validate.exit_code, 0) << validate.err;
  EXPECT_NE(validate.out.find("warning: materials 'VeroWhite' and 'Agilus30White' have nearly the same colour"),
            std::string::npos)
      << validate.out;
  const CliResult slice =
      run_cli("slice " + shell_quote(scene) + " -o " + shell_quote(dir.path() / "out") + " -q --layers 1:2");
  EXPECT_EQ(slice.exit_code, 0) << slice.err;
  EXPECT_NE(slice.err.find("trivox: warning: materials 'VeroWhite' and 'Agilus30White'"), std::string::npos)
      << slice.err;
  const CliResult plain =
      run_cli("validate " + shell_quote(examples_dir() / "scenes" / "box_gradient.json") + " --samples 0");
  EXPECT_EQ(plain.out.find("warning"), std::string::npos) << plain.out;
}

// A scene whose sum exceeds 1 only in a thin band: validate finds a point in it, names the
// cell, the parameters and the position, and fails, where it used to say "ok".
std::string bar_scene(const std::string& a, const std::string& b) {
  return R"({ "units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [ { "name": "bar", "geometry": { "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
      "points": [[0, 0, 0], [40, 0, 0], [0, 10, 0], [40, 10, 0], [0, 0, 5], [40, 0, 5], [0, 10, 5], [40, 10, 5]] },
    "material": { "kind": "expression", "fractions": { "VeroCyan": ")" +
         a + R"(", "VeroMagenta": ")" + b + R"(" } } } ] })";
}

TEST(CliFirstHour, ValidateProvesTheFractionSumsOrSaysItCannot) {
  ScratchDir dir;
  const fs::path band = dir.path() / "band.json";
  write_text(band, bar_scene("u + (abs(w - 0.37) < 0.002 ? 0.5 : 0)", "1 - u"));
  const CliResult broken = run_cli("validate " + shell_quote(band) + " --samples 0");
  EXPECT_EQ(broken.exit_code, 3) << broken.out << broken.err;
  for (const char* part : {"/cells/0/material", "cell 'bar'", "the fractions sum to 1.5", "(u,v,w) = (", "(x,y,z) = (",
                           " mm", "normalise"})
    EXPECT_NE(broken.err.find(part), std::string::npos) << part << " in " << broken.err;
  EXPECT_EQ(broken.out.find("ok:"), std::string::npos) << broken.out;

  const fs::path trig = dir.path() / "trig.json";
  write_text(trig, bar_scene("sin(x)^2", "cos(x)^2"));
  const CliResult unproved = run_cli("validate " + shell_quote(trig) + " --samples 0");
  EXPECT_EQ(unproved.exit_code, 0) << unproved.err;
  EXPECT_NE(unproved.out.find("cell 'bar' (/cells/0/material): cannot prove: the sum may reach"), std::string::npos)
      << unproved.out;
  EXPECT_NE(unproved.out.find("\ncannot prove: the fraction sums of 1 cell"), std::string::npos) << unproved.out;
  EXPECT_EQ(unproved.out.find("ok:"), std::string::npos) << unproved.out;

  const fs::path fine = dir.path() / "fine.json";
  write_text(fine, bar_scene("1 - u", "u"));
  const CliResult ok = run_cli("validate " + shell_quote(fine) + " --samples 0");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("fraction sums: 1 of 1 cells proved"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("\nok: the job can run"), std::string::npos) << ok.out;
}

// Slicing the same scene meets the bad band: it stops at once, says where (cell, layer,
// position, parameters) and how to go on; with the policy corrected to "normalise" the same
// command with --resume keeps the completed layers and finishes.
TEST(CliFirstHour, SliceStopsAtABadSumAndResumesAfterTheCorrection) {
  ScratchDir dir;
  const fs::path scene = dir.path() / "band.json";
  write_text(scene, bar_scene("u + (abs(w - 0.37) < 0.002 ? 0.5 : 0)", "1 - u"));
  const fs::path out = dir.path() / "out";
  const std::string args = "slice " + shell_quote(scene) + " -o " + shell_quote(out) + " -q";
  const CliResult stopped = run_cli(args);
  EXPECT_EQ(stopped.exit_code, 3) << stopped.err;
  for (const char* part : {"/cells/0/material: cell 'bar': layer ", " (z = ", "the fractions sum to 1.5", "(u,v,w) = (",
                           "(x,y,z) = (", " mm", "marked failed", "--resume"})
    EXPECT_NE(stopped.err.find(part), std::string::npos) << part << " in " << stopped.err;
  EXPECT_NE(read_text(out / "manifest.json").find("\"failed\""), std::string::npos);
  EXPECT_EQ(run_cli("verify " + shell_quote(out)).exit_code, 5);

  nlohmann::json j = nlohmann::json::parse(read_text(scene));
  j["fraction_sums"] = {{"policy", "normalise"}};
  write_text(scene, j.dump(2));
  const CliResult resumed = run_cli(args + " --resume");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err << resumed.out;
  EXPECT_NE(resumed.out.find("layers were already complete"), std::string::npos) << resumed.out;
  EXPECT_EQ(run_cli("verify " + shell_quote(out)).exit_code, 0);
}

}  // namespace
}  // namespace trivox::test
