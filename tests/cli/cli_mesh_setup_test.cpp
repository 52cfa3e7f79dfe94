// Setting up a mesh trim from the command line: `trivox info MESH` describes the mesh (format,
// counts, box, the checks of a mesh trim) and `trivox init --mesh MESH` writes a scene that
// fills the part the mesh encloses, framed by the mesh's box (docs/CLI.md, "info", "init").
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "mesh/mesh_fixtures.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

TEST(CliMeshSetup, InfoDescribesAMeshAndItsChecks) {
  ScratchDir dir;
  write_bytes(dir.path() / "part.stl", binary_stl(box_mesh({1, 2, 3}, {2, 4, 7})));
  const CliResult r = run_cli("info " + shell_quote(dir.path() / "part.stl"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("part.stl: binary STL, 12 triangles, 8 vertices\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bounds: x [1, 2], y [2, 4], z [3, 7] mm; size 1 x 2 x 4 mm\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("closed: yes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("self-intersections: none (longer than 0.027 mm, the finest pitch of printer j750-hm)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("passes:"), std::string::npos) << r.out;

  // A box with one triangle missing: open, named with an example, and the rule that takes it.
  TestMesh open = box_mesh({0, 0, 0}, {1, 1, 1});
  open.triangles.pop_back();
  write_bytes(dir.path() / "open.stl", binary_stl(open));
  const CliResult o = run_cli("info " + shell_quote(dir.path() / "open.stl") + " --printer sl1s");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("closed: no (open edges: 3, non-manifold edges: none)"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("fails: not closed: 3 open edges, each on one triangle only (e.g. triangle "), std::string::npos)
      << o.out;
  EXPECT_NE(o.out.find("\"winding-number\""), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("printer sl1s"), std::string::npos) << o.out;

  const CliResult j = run_cli("info --json " + shell_quote(dir.path() / "open.stl"));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const nlohmann::json doc = nlohmann::json::parse(j.out);
  EXPECT_EQ(doc.at("format"), "binary STL");
  EXPECT_EQ(doc.at("triangles"), 11);
  EXPECT_EQ(doc.at("bounds").at("size_mm"), nlohmann::json::array({1.0, 1.0, 1.0}));
  EXPECT_EQ(doc.at("checks").at("closed"), false);
  EXPECT_EQ(doc.at("checks").at("open_edges"), 3);
  EXPECT_EQ(doc.at("checks").at("passed"), false);

  EXPECT_EQ(run_cli("info " + shell_quote(dir.path() / "part.stl") + " --printer nope").exit_code, 2);
  // A mesh that cannot be read names the file.
  write_text(dir.path() / "bad.stl", "solid x\nfacet normal 0 0 1\n");
  const CliResult bad = run_cli("info " + shell_quote(dir.path() / "bad.stl"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("bad.stl"), std::string::npos) << bad.err;
}

TEST(CliMeshSetup, InitWritesAMeshSceneFramedByTheMeshThatSlicesAsIs) {
  ScratchDir dir;
  fs::create_directories(dir.path() / "meshes");
  write_bytes(dir.path() / "meshes" / "part.stl", binary_stl(box_mesh({1, 2, 3}, {2, 4, 5})));
  const fs::path scene = dir.path() / "part.json";
  const CliResult r = run_cli("init --mesh " + shell_quote(dir.path() / "meshes" / "part.stl") + " " +
                              shell_quote(scene) + " --materials VeroCyan,VeroMagenta");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("encloses (1 x 2 x 2 mm, its box) graded from VeroCyan at its bottom to VeroMagenta at its top"),
            std::string::npos)
      << r.out;
  const nlohmann::json doc = nlohmann::json::parse(read_text(scene));
  const nlohmann::json& cell = doc.at("cells").at(0);
  EXPECT_EQ(cell.at("geometry").at("bounding_box").at("mesh"), "meshes/part.stl");  // relative to the scene
  EXPECT_EQ(cell.at("trim").at(0).at("shell").at("mesh"), "meshes/part.stl");
  EXPECT_FALSE(cell.at("trim").at(0).at("shell").contains("inside_rule"));
  const fs::path out = dir.path() / "out";
  const CliResult s = run_cli("slice " + shell_quote(scene) + " -q --min-layers 0 -o " + shell_quote(out));
  ASSERT_EQ(s.exit_code, 0) << s.err;
  // Framed by the mesh: 2 mm tall at 27 um is 75 layers; the model's size is the mesh's.
  EXPECT_NE(s.out.find("sliced 75 layers"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("model: 1.00 x 2.00 x 2.00 mm"), std::string::npos) << s.out;

  // An open mesh gets the winding-number rule, and the note says why.
  TestMesh open = box_mesh({0, 0, 0}, {1, 1, 1});
  open.triangles.pop_back();
  write_bytes(dir.path() / "open.stl", binary_stl(open));
  const CliResult o =
      run_cli("init --mesh " + shell_quote(dir.path() / "open.stl") + " " + shell_quote(dir.path() / "open.json"));
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("note: the mesh is not closed: 3 open edges"), std::string::npos) << o.out;
  EXPECT_EQ(nlohmann::json::parse(read_text(dir.path() / "open.json"))
                .at("cells")
                .at(0)
                .at("trim")
                .at(0)
                .at("shell")
                .at("inside_rule"),
            "winding-number");
  EXPECT_EQ(run_cli("validate " + shell_quote(dir.path() / "open.json")).exit_code, 0);
  // A missing mesh writes nothing.
  const CliResult missing =
      run_cli("init --mesh " + shell_quote(dir.path() / "none.stl") + " " + shell_quote(dir.path() / "none.json"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_FALSE(fs::exists(dir.path() / "none.json"));
}

}  // namespace
}  // namespace trivox::test
