// Mesh trims in scene files (docs/SCENE.md, "Mesh trims"): a shell {"mesh": F, "placement",
// "inside_rule"} read, placed and hashed; the meshes the even-odd rule refuses, each with its
// count, an example triangle and the option to name; and the keys a mesh shell may not have.
// The meshes are written here (tests/mesh/mesh_fixtures.h), so no shared data is needed.
#include <gtest/gtest.h>

#include "mesh/mesh_fixtures.h"
#include "scene/scene_test_util.h"
#include "trivox/io/detail/sha256.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

std::string scene_with_trim(const std::string& clause) {
  return R"({"version": 1, "units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
  "cells": [{"name": "c", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0], [0, 0, 4], [4, 0, 4], [0, 4, 4], [4, 4, 4]]},
    "material": "VeroCyan", "trim": [)" +
         clause + "]}]}";
}

class SceneMeshTrim : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir(); }
  fs::path write_stl(const std::string& name, const test::TestMesh& m) {
    test::write_bytes(dir_ / name, test::binary_stl(m));
    return dir_ / name;
  }
  Scene parse(const std::string& clause) { return parse_scene(scene_with_trim(clause), dir_ / "scene.json"); }
  void expect_error(const std::string& clause, const std::string& pointer, const std::string& fragment) {
    test::expect_scene_error(scene_with_trim(clause), pointer, fragment, dir_);
  }
  fs::path dir_;
};

TEST_F(SceneMeshTrim, AMeshShellIsReadPlacedAndHashed) {
  const fs::path stl = write_stl("box.stl", test::box_mesh({0, 0, 0}, {1, 2, 3}));
  const Scene s =
      parse(R"({"side": "outside", "shell": {"mesh": "box.stl", "placement": {"translate": [1, 0.5, 0.25]}}})");
  ASSERT_EQ(s.cells[0].trim.clauses.size(), 1u);
  const TrimClause& k = s.cells[0].trim.clauses[0];
  EXPECT_EQ(k.kind, TrimKind::kShell);
  EXPECT_EQ(k.side, TrimSide::kOutside);
  ASSERT_TRUE(k.shell->mesh);
  EXPECT_EQ(k.shell->rule, InsideRule::kEvenOdd);
  EXPECT_EQ(k.shell->mesh->triangles().size(), 12u);
  EXPECT_EQ(k.shell->mesh->bounds().lo, (Vec3{1, 0.5, 0.25}));
  EXPECT_EQ(k.shell->mesh->bounds().hi, (Vec3{2, 2.5, 3.25}));
  ASSERT_EQ(s.input_files.size(), 1u);
  EXPECT_EQ(s.input_files[0].name, "box.stl");
  EXPECT_EQ(s.input_files[0].sha256, sha256_file(stl).sha256);

  const Scene w = parse(R"({"side": "inside", "shell": {"mesh": "box.stl", "inside_rule": "winding-number"}})");
  EXPECT_EQ(w.cells[0].trim.clauses[0].shell->rule, InsideRule::kWindingNumber);
}

TEST_F(SceneMeshTrim, TheEvenOddRuleRefusesAMeshThatIsNotASolidAndNamesTheOption) {
  // Two boxes that overlap: closed and oriented, but crossing each other.
  test::TestMesh two = test::box_mesh({0, 0, 0}, {2, 2, 2});
  const test::TestMesh other = test::box_mesh({1, 1, 1}, {3, 3, 3});
  for (const Vec3& p : other.vertices) two.vertices.push_back(p);
  for (const auto& t : other.triangles) two.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  write_stl("two.stl", two);
  expect_error(R"({"side": "inside", "shell": {"mesh": "two.stl"}})", "/cells/0/trim/0/shell/mesh",
               "is self-intersecting: ");
  expect_error(R"({"side": "inside", "shell": {"mesh": "two.stl"}})", "/cells/0/trim/0/shell/mesh",
               "Give the shell \"inside_rule\": \"winding-number\"");
  EXPECT_NO_THROW(parse(R"({"side": "inside", "shell": {"mesh": "two.stl", "inside_rule": "winding-number"}})"));

  // A box without its last triangle: three open edges, the lowest triangle beside the hole
  // named with its corners (1-based, as the file numbers them).
  test::TestMesh open = test::box_mesh({0, 0, 0}, {1, 1, 1});
  open.triangles.pop_back();
  write_stl("open.stl", open);
  expect_error(R"({"side": "inside", "shell": {"mesh": "open.stl"}})", "/cells/0/trim/0/shell/mesh",
               "not closed: 3 open edges, each on one triangle only (e.g. triangle ");
  EXPECT_NO_THROW(parse(R"({"side": "inside", "shell": {"mesh": "open.stl", "inside_rule": "winding-number"}})"));

  // One triangle flipped.
  test::TestMesh flipped = test::box_mesh({0, 0, 0}, {1, 1, 1});
  std::swap(flipped.triangles[5][0], flipped.triangles[5][1]);
  write_stl("flipped.stl", flipped);
  expect_error(R"({"side": "inside", "shell": {"mesh": "flipped.stl"}})", "/cells/0/trim/0/shell/mesh",
               "not consistently oriented: 3 edges");
}

TEST_F(SceneMeshTrim, KeysAndPlacesAMeshMayNotHave) {
  write_stl("box.stl", test::box_mesh({0, 0, 0}, {1, 1, 1}));
  expect_error(R"({"side": "inside", "shell": {"mesh": "box.stl", "inside_rule": "nonzero"}})",
               "/cells/0/trim/0/shell/inside_rule", "expected \"even-odd\" or \"winding-number\"");
  expect_error(R"({"side": "inside", "shell": {"mesh": "box.stl", "surfaces": []}})", "/cells/0/trim/0/shell/surfaces",
               "unknown key \"surfaces\"");
  expect_error(R"({"side": "inside", "parametric": {"mesh": "box.stl"}})", "/cells/0/trim/0/parametric/mesh",
               "a triangle mesh trims in model space");
  expect_error(R"({"side": "inside", "shell": {"file": "box.stl"}})", "/cells/0/trim/0/shell/file",
               "is a triangle mesh: give it as {\"mesh\": \"box.stl\"}");
  expect_error(R"({"side": "inside", "shell": {"mesh": "absent.stl"}})", "/cells/0/trim/0/shell/mesh", "absent.stl");
  test::write_file(dir_ / "bad.stl", "not a mesh at all");
  expect_error(R"({"side": "inside", "shell": {"mesh": "bad.stl"}})", "/cells/0/trim/0/shell/mesh",
               "neither a binary STL");
}

// A part exported twice (every triangle doubled) is refused as doubled, with an example.
TEST_F(SceneMeshTrim, AMeshExportedTwiceIsRefusedAsDoubled) {
  test::TestMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const auto once = m.triangles;
  m.triangles.insert(m.triangles.end(), once.begin(), once.end());
  write_stl("twice.stl", m);
  expect_error(R"({"side": "inside", "shell": {"mesh": "twice.stl"}})", "/cells/0/trim/0/shell/mesh",
               "doubled: 12 triangles repeat the corners of an earlier one");
}

// A mesh placed 1e300 mm away loses the precision its triangles need, and is refused as such,
// not as self-intersecting; a placement that overflows is refused as overflowing, not singular.
TEST_F(SceneMeshTrim, AMeshPlacedWhereDoublesLosePrecisionIsRefusedAsSuch) {
  write_stl("box.stl", test::box_mesh({0, 0, 0}, {1, 1, 1}));
  expect_error(R"({"side": "inside", "shell": {"mesh": "box.stl", "placement": {"translate": [1e300, 0, 0]}}})",
               "/cells/0/trim/0/shell/mesh", "lose the precision its triangles need");
  expect_error(R"({"side": "inside", "shell": {"mesh": "box.stl", "placement": {"scale": 1e300}}})",
               "/cells/0/trim/0/shell/placement", "the placement overflows");
}

// {"bounding_box": {"mesh", "placement", "margin_mm"}}: the trilinear box around the placed
// mesh, u, v, w along x, y, z; the mesh is read once for the box and the trim and hashed once.
TEST_F(SceneMeshTrim, ABoundingBoxIsTheBoxAroundThePlacedMesh) {
  write_stl("part.stl", test::box_mesh({1, 2, 3}, {2, 4, 7}));
  const auto scene_text = [](const std::string& box) {
    return R"({"version": 1, "units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
      "cells": [{"name": "c", "geometry": {"bounding_box": )" +
           box + R"(}, "material": "VeroCyan",
      "trim": [{"side": "inside", "shell": {"mesh": "part.stl", "placement": {"scale": 2}}}]}]})";
  };
  const Scene s =
      parse_scene(scene_text(R"({"mesh": "part.stl", "placement": {"scale": 2}, "margin_mm": 0.5})"), dir_ / "s.json");
  const Box3 box = s.cells[0].volume.bounds();
  EXPECT_EQ(box.lo, (Vec3{1.5, 3.5, 5.5}));
  EXPECT_EQ(box.hi, (Vec3{4.5, 8.5, 14.5}));
  // u runs along x, v along y, w along z.
  const Vec3 p = s.cells[0].volume.evaluate({0.25, 0.5, 1.0});
  EXPECT_DOUBLE_EQ(p.x, 2.25);
  EXPECT_DOUBLE_EQ(p.y, 6.0);
  EXPECT_DOUBLE_EQ(p.z, 14.5);
  ASSERT_EQ(s.input_files.size(), 1u);
  EXPECT_EQ(s.input_files[0].name, "part.stl");
  // Without a margin the box is the mesh's.
  const Scene tight = parse_scene(scene_text(R"({"mesh": "part.stl", "placement": {"scale": 2}})"), dir_ / "t.json");
  EXPECT_EQ(tight.cells[0].volume.bounds().lo, (Vec3{2, 4, 6}));
  EXPECT_EQ(tight.cells[0].volume.bounds().hi, (Vec3{4, 8, 14}));

  test::expect_scene_error(scene_text(R"({"mesh": "part.stl", "margin_mm": -1})"),
                           "/cells/0/geometry/bounding_box/margin_mm", "expected a margin >= 0 mm", dir_);
  test::expect_scene_error(scene_text(R"({"mesh": "part.stl", "scale": 2})"), "/cells/0/geometry/bounding_box/scale",
                           "unknown key", dir_);
  test::expect_scene_error(scene_text(R"({"mesh": "none.stl"})"), "/cells/0/geometry/bounding_box/mesh",
                           "there is no file", dir_);
  // A flat mesh (one triangle) has a box without interior unless given a margin.
  test::TestMesh flat;
  flat.vertices = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  flat.triangles = {{0, 1, 2}};
  write_stl("flat.stl", flat);
  test::expect_scene_error(scene_text(R"({"mesh": "flat.stl"})"), "/cells/0/geometry/bounding_box/mesh",
                           "is flat (1 x 1 x 0 mm where it is placed)", dir_);
}

}  // namespace
}  // namespace trivox
