// Reading triangle meshes (trivox/io/triangle_mesh.h): the same box from every format, files
// written here from the formats' specifications; 3MF placement, components and units; the
// exact weld; and the sizes a file declares checked before anything is allocated.
#include <gtest/gtest.h>

#include <filesystem>
#include <tuple>

#include "mesh/mesh_fixtures.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/limits.h"
#include "trivox/mesh/detail/mesh_check.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

class TriangleMeshRead : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("trivox_mesh_read_{}", ::getpid());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    test::write_bytes(p, bytes);
    return p;
  }
  fs::path dir_;
};

// The box [1, 3] x [-2, 0.5] x [0, 4]: every coordinate a float, so every format keeps it.
test::TestMesh the_box() { return test::box_mesh({1, -2, 0}, {3, 0.5, 4}); }

void expect_the_box(const TriangleMeshFile& f, Vec3 lo = {1, -2, 0}, Vec3 hi = {3, 0.5, 4}) {
  EXPECT_EQ(f.triangles.size(), 12u) << f.source;
  EXPECT_EQ(f.vertices.size(), 8u) << f.source;
  Box3 b;
  for (const Vec3& p : f.vertices) b.expand(p);
  EXPECT_EQ(b.lo, lo) << f.source;
  EXPECT_EQ(b.hi, hi) << f.source;
  const MeshCheck c = check_mesh(SlicedMesh(f.vertices, f.triangles), {});
  EXPECT_TRUE(c.passed()) << f.source << ": " << c.open_edges.count << " open, " << c.misoriented_edges.count
                          << " misoriented";
  // Counter-clockwise from outside, as written: a positive volume.
  double volume = 0;
  for (const auto& t : f.triangles)
    volume += dot(f.vertices[static_cast<std::size_t>(t[0])],
                  cross(f.vertices[static_cast<std::size_t>(t[1])], f.vertices[static_cast<std::size_t>(t[2])]));
  EXPECT_NEAR(volume / 6, 2 * 2.5 * 4, 1e-9) << f.source;
}

TEST_F(TriangleMeshRead, TheSameBoxFromEveryFormat) {
  const test::TestMesh m = the_box();
  expect_the_box(read_triangle_mesh(file("box.stl", test::binary_stl(m))));
  EXPECT_EQ(read_triangle_mesh(file("box_b.stl", test::binary_stl(m))).format, "binary STL");
  // A binary file whose header starts with "solid" is still binary: its size says so.
  const TriangleMeshFile solid_header = read_triangle_mesh(file("solid.stl", test::binary_stl(m, "solid header")));
  EXPECT_EQ(solid_header.format, "binary STL");
  expect_the_box(solid_header);
  const TriangleMeshFile ascii = read_triangle_mesh(file("box_a.STL", test::ascii_stl(m)));
  EXPECT_EQ(ascii.format, "ASCII STL");
  expect_the_box(ascii);
  expect_the_box(read_triangle_mesh(file("box.obj", test::obj_text(m))));
  expect_the_box(read_triangle_mesh(file("box.ply", test::ply_ascii(m))));
  expect_the_box(read_triangle_mesh(file("box_bin.ply", test::ply_binary(m))));
  test::write_3mf(dir_ / "box.3mf",
                  "<?xml version=\"1.0\" encoding=\"UTF-8\"?><model unit=\"millimeter\" "
                  "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\"><resources><object id=\"1\" "
                  "type=\"model\">" +
                      test::threemf_mesh(m) + "</object></resources><build><item objectid=\"1\"/></build></model>");
  expect_the_box(read_triangle_mesh(dir_ / "box.3mf"));
}

TEST_F(TriangleMeshRead, ObjQuadsAreSplitIntoTriangles) {
  // The box's six faces as quads (counter-clockwise from outside).
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
  obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  const TriangleMeshFile f = read_triangle_mesh(file("quads.obj", obj));
  EXPECT_EQ(f.triangles.size(), 12u);
  EXPECT_TRUE(check_mesh(SlicedMesh(f.vertices, f.triangles), {}).passed());
}

// The production extension's UUIDs, as lib3mf and slicers write them: assimp 5.2's importer
// returns an empty scene for this file, which is why 3MF goes through lib3mf.
TEST_F(TriangleMeshRead, ThreeMfWithTheProductionExtension) {
  const test::TestMesh m = the_box();
  test::write_3mf(
      dir_ / "p.3mf",
      "<?xml version=\"1.0\" encoding=\"utf-8\"?><model "
      "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\" "
      "unit=\"millimeter\" xml:lang=\"en-US\" "
      "xmlns:p=\"http://schemas.microsoft.com/3dmanufacturing/production/2015/06\" "
      "requiredextensions=\"\"><resources><object id=\"1\" type=\"model\" "
      "p:UUID=\"5f9c621a-7fe3-4e58-915c-2c8c43dd0188\">" +
          test::threemf_mesh(m) +
          "</object></resources><build p:UUID=\"2bb97571-1c4d-4016-b4e0-f4ecaccd407b\"><item objectid=\"1\" "
          "p:UUID=\"448423f5-73c3-45af-8466-1a5688f4c6e9\"/></build></model>");
  expect_the_box(read_triangle_mesh(dir_ / "p.3mf"));
}

TEST_F(TriangleMeshRead, ThreeMfBuildItemsComponentsAndUnits) {
  const test::TestMesh unit_cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  // Object 2 holds the cube twice: as it is, and turned a quarter about z (x' = -y, y' = x)
  // and moved by (0, 0, 5). The build places object 2 moved by (10, 0, 0), in centimetres.
  // 3MF matrices are "m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32" for row vectors.
  test::write_3mf(dir_ / "c.3mf",
                  "<?xml version=\"1.0\" encoding=\"UTF-8\"?><model unit=\"centimeter\" "
                  "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\"><resources><object id=\"1\" "
                  "type=\"model\">" +
                      test::threemf_mesh(unit_cube) +
                      "</object><object id=\"2\" type=\"model\"><components><component objectid=\"1\"/>"
                      "<component objectid=\"1\" transform=\"0 1 0 -1 0 0 0 0 1 0 0 5\"/></components></object>"
                      "<object id=\"3\" type=\"support\">" +
                      test::threemf_mesh(unit_cube) +
                      "</object></resources><build><item objectid=\"2\" transform=\"1 0 0 0 1 0 0 0 1 10 0 0\"/>"
                      "<item objectid=\"3\"/></build></model>");
  const TriangleMeshFile f = read_triangle_mesh(dir_ / "c.3mf");
  EXPECT_EQ(f.format, "3MF");
  ASSERT_EQ(f.triangles.size(), 24u);  // the support object is not part of the solid
  Box3 first, second;
  for (std::size_t t = 0; t < 12; ++t)
    for (int v : f.triangles[t]) first.expand(f.vertices[static_cast<std::size_t>(v)]);
  for (std::size_t t = 12; t < 24; ++t)
    for (int v : f.triangles[t]) second.expand(f.vertices[static_cast<std::size_t>(v)]);
  EXPECT_EQ(first.lo, (Vec3{100, 0, 0}));
  EXPECT_EQ(first.hi, (Vec3{110, 10, 10}));
  EXPECT_EQ(second.lo, (Vec3{90, 0, 50}));
  EXPECT_EQ(second.hi, (Vec3{100, 10, 60}));
  // The turn keeps each cube closed and outward.
  EXPECT_TRUE(check_mesh(SlicedMesh(f.vertices, f.triangles), {}).closed());
  EXPECT_EQ(check_mesh(SlicedMesh(f.vertices, f.triangles), {}).misoriented_edges.count, 0u);
}

TEST_F(TriangleMeshRead, WeldsExactlyEqualVerticesOnly) {
  // Two triangles sharing an edge, one of them with -0 where the other has 0; and a third
  // whose corner differs from theirs in the last bit of a float.
  test::TestMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-0.0, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {1, 3, 5}, {4, 1, 5}};
  const float next = std::nextafter(1.0f, 2.0f);
  m.vertices.push_back({next, 1, 0});
  m.triangles.push_back({1, 6, 3});
  const TriangleMeshFile f = read_triangle_mesh(file("weld.stl", test::binary_stl(m)));
  ASSERT_EQ(f.triangles.size(), 4u);
  EXPECT_EQ(f.vertices.size(), 5u);  // (0,0,0) = (-0,0,0), (0,1,0) twice; (next,1,0) its own
  EXPECT_EQ(f.triangles[2][0], f.triangles[0][0]);
  EXPECT_EQ(f.dropped_degenerate, 0u);
}

TEST_F(TriangleMeshRead, DropsAndCountsTrianglesWithARepeatedVertex) {
  test::TestMesh m = the_box();
  m.triangles.push_back({0, 0, 1});
  m.triangles.push_back({2, 3, 2});
  const TriangleMeshFile f = read_triangle_mesh(file("degenerate.stl", test::binary_stl(m)));
  EXPECT_EQ(f.dropped_degenerate, 2u);
  expect_the_box(f);
}

void expect_input_error(const fs::path& path, const std::string& part) {
  try {
    read_triangle_mesh(path);
    ADD_FAILURE() << path << ": no error";
  } catch (const UnsupportedError& e) {
    ADD_FAILURE() << path << ": unsupported, " << e.what();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST_F(TriangleMeshRead, RefusesMalformedFilesNamingTheFileAndTheRule) {
  std::string stl = test::binary_stl(the_box());
  expect_input_error(file("short.stl", stl.substr(0, stl.size() - 1)), "neither a binary STL");
  // A count of 2^32 - 1 triangles in a file of a few hundred bytes: refused from the size,
  // before anything is allocated for it.
  std::string huge = stl;
  for (int i = 80; i < 84; ++i) huge[static_cast<std::size_t>(i)] = '\xFF';
  expect_input_error(file("huge.stl", huge), "4294967295 triangles");
  expect_input_error(file("empty.stl", ""), "neither a binary STL");
  expect_input_error(file("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), "not finite");
  expect_input_error(file("points.obj", "v 0 0 0\nv 1 0 0\np 1\np 2\n"), "no triangle");
  expect_input_error(file("bad.obj", "v 0 0 0\nf 1 2 3\n"), "OBJ");
  std::string ply = test::ply_binary(the_box());
  const auto at = ply.find("element vertex 8");
  ply.replace(at, 16, "element vertex 99999999999");
  expect_input_error(file("count.ply", ply), "99999999999 entries");
  expect_input_error(file("notazip.3mf", "this is not a zip file"), "3MF");
  EXPECT_THROW(read_triangle_mesh(file("box.off", "OFF\n")), UnsupportedError);
  EXPECT_THROW(read_triangle_mesh(dir_ / "absent.stl"), IoError);
}

TEST(TriangleMeshLimits, TheBudgetIsCheckedBeforeAllocation) {
  // More triangles than kMaxMeshTriangles, declared by a binary STL whose size matches: the
  // file is never read beyond its header (the bytes are not there).
  static_assert(kMaxMeshTriangles < (std::int64_t{1} << 32));
  std::string header(80, 'x');
  const auto n = static_cast<std::uint32_t>(kMaxMeshTriangles + 1);
  for (int i = 0; i < 4; ++i) header.push_back(static_cast<char>((n >> (8 * i)) & 0xFF));
  // A span that claims the full size: read_triangle_mesh checks the count from the header and
  // the size alone. (Only the header's bytes exist; the rest of the span is never touched.)
  const std::size_t claimed = 84 + 50 * std::size_t{n};
  std::vector<std::uint8_t> bytes(header.begin(), header.end());
  const std::span<const std::uint8_t> view(bytes.data(), claimed);
  try {
    read_triangle_mesh(view, ".stl", "claimed.stl");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than the"), std::string::npos) << e.what();
  }
}

TEST(TriangleMeshShared, TheFiveSharedMeshesReadClosed) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  // Triangles and vertices: F = 2 (V - 2 + 2 g) for a closed mesh of genus g (the torus has 1).
  const std::tuple<const char*, std::size_t, std::size_t> meshes[] = {{"bunny.stl", 292, 148},
                                                                      {"torus.stl", 3072, 1536},
                                                                      {"M3_hex_nut.stl", 620, 312},
                                                                      {"sphere.stl", 1224, 614},
                                                                      {"box.stl", 12, 8}};
  for (const auto& [name, triangles, vertices] : meshes) {
    const TriangleMeshFile f = read_triangle_mesh(dir / "meshes" / name);
    EXPECT_EQ(f.format, "binary STL");
    EXPECT_EQ(f.triangles.size(), triangles) << name;
    EXPECT_EQ(f.vertices.size(), vertices) << name;
    const MeshCheck c = check_mesh(SlicedMesh(f.vertices, f.triangles), {0.01, true});
    EXPECT_TRUE(c.passed()) << name << ": " << c.open_edges.count << " open, " << c.nonmanifold_edges.count
                            << " non-manifold, " << c.misoriented_edges.count << " misoriented, "
                            << c.self_intersections.count << " intersecting";
    // The same triangles as an independent reading of the file.
    const auto soup = test::read_stl_soup(dir / "meshes" / name);
    ASSERT_EQ(soup.size(), f.triangles.size());
    for (std::size_t t = 0; t < soup.size(); ++t)
      for (std::size_t k = 0; k < 3; ++k)
        ASSERT_EQ(soup[t][k], f.vertices[static_cast<std::size_t>(f.triangles[t][k])]) << name << " triangle " << t;
  }
}

}  // namespace
}  // namespace trivox
