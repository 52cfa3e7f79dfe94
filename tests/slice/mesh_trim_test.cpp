// Mesh trims end to end: a box cell trimmed by each of the five meshes of ../shared/data/meshes
// (scaled to about 12 mm), sliced by the even-odd and by the winding-number rule, against an
// independent point-in-solid test on the same pixel centres: ray parity with every
// orientation decided exactly (tests/mesh/mesh_fixtures.h), on triangles read from the STL
// here. A pixel is material exactly when its centre lies inside the box and inside the mesh;
// the comparison is exact away from the surface: only pixels whose row passes within 1e-7 mm
// of the surface (where rounding could move a crossing past the centre) or whose centre lies
// within that of the box's faces are left out, and there are none or a handful.
//
// Then the reports: a mesh with a triangle missing, or one flipped, is refused by the
// even-odd rule with the count, an example triangle and the option to name; by the
// winding-number rule it slices as the closed mesh does.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <iostream>
#include <map>

#include "mesh/mesh_fixtures.h"
#include "slice/mesh_trim_fixtures.h"
#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;
using test::cell_box;
using test::kMeshes;
using test::placed;
using test::scene_json;
using test::SharedMesh;

struct Occupancy {
  std::int64_t checked = 0, inside = 0, left_out = 0, mismatches = 0;
};

// Slices `layers` layers spread over the scene and compares every pixel with the rays.
Occupancy compare(const Scene& scene, const test::ExactRays& rays, const Box3& box, int layers,
                  const std::string& what) {
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  Occupancy o;
  for (int i = 0; i < layers; ++i) {
    const int layer = (2 * i + 1) * L.num_layers / (2 * layers);
    const double z = L.z_of_layer(layer);
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const Vec3 p{L.x_of_col(col), L.y_of_row(row), z};
        bool degenerate;
        double nearest;
        const bool in_mesh = rays.inside(p, degenerate, nearest);
        const double margin = 1e-7;
        const bool near_box = std::abs(p.x - box.lo.x) < margin || std::abs(p.x - box.hi.x) < margin ||
                              std::abs(p.y - box.lo.y) < margin || std::abs(p.y - box.hi.y) < margin ||
                              std::abs(p.z - box.lo.z) < margin || std::abs(p.z - box.hi.z) < margin;
        if (degenerate || nearest < margin || near_box) {
          ++o.left_out;
          continue;
        }
        const bool in_box =
            p.x > box.lo.x && p.x < box.hi.x && p.y > box.lo.y && p.y < box.hi.y && p.z > box.lo.z && p.z < box.hi.z;
        const bool want = in_mesh && in_box;
        const bool got = owner[static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) +
                               static_cast<std::size_t>(col)] == 0;
        ++o.checked;
        o.inside += want;
        if (got != want && ++o.mismatches <= 5)
          ADD_FAILURE() << what << ": layer " << layer << " pixel " << col << ", " << row << " (" << p.x << ", " << p.y
                        << ", " << p.z << "): sliced " << (got ? "inside" : "outside") << ", exact rays say "
                        << (want ? "inside" : "outside");
      }
  }
  return o;
}

TEST(MeshTrim, OccupancyOfTheFiveSharedMeshesAgreesWithExactRays) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  for (const SharedMesh& m : kMeshes) {
    const fs::path path = dir / "meshes" / m.name;
    const auto soup = placed(test::read_stl_soup(path), m.scale);
    const test::ExactRays rays(soup);
    const Box3 box = cell_box(soup);
    for (const std::string rule : {"even-odd", "winding-number"}) {
      const Scene scene = parse_scene(scene_json(path, m.scale, box, rule), "mesh_trim.json");
      const Occupancy o = compare(scene, rays, box, 6, fmt::format("{} ({})", m.name, rule));
      std::cout << m.name << " (" << rule << "): " << o.checked << " pixels checked, " << o.inside
                << " inside the mesh and the box, " << o.left_out << " left out at the surface, " << o.mismatches
                << " disagree\n";
      EXPECT_EQ(o.mismatches, 0) << m.name << " " << rule;
      EXPECT_GT(o.inside, 1000) << m.name << " " << rule;
      if (std::string(m.name) == "box.stl" && rule == "even-odd") {
        // The frame is what the cell keeps, the box mesh's own box cut by the cell's (a mesh
        // decided by its winding number does not narrow it): every pixel in it is inside, and
        // the mesh's faces, laid out from its corner, may carry a row of pixel centres the rays
        // cannot decide (left out), but no more than a few rows.
        EXPECT_EQ(o.checked, o.inside) << rule;
        EXPECT_LT(o.left_out, o.checked / 20) << rule;
      } else {
        EXPECT_GT(o.checked - o.inside, 10000) << m.name << " " << rule;
        EXPECT_LT(o.left_out, 10) << m.name << " " << rule;
      }
    }
  }
}

// The same comparison without the shared meshes: a sphere of 40 x 64 facets written here as
// a binary STL, whole and with a triangle missing (which only the winding-number rule takes),
// against exact rays on the whole sphere's triangles.
TEST(MeshTrim, OccupancyOfAWrittenSphereAgreesWithExactRays) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox_mesh_trim_sphere_{}", ::getpid());
  fs::create_directories(dir);
  test::TestMesh sphere = test::sphere_mesh({3.1, 2.3, 4.2}, 4, 40, 64);
  test::write_bytes(dir / "sphere.stl", test::binary_stl(sphere));
  sphere.triangles.erase(sphere.triangles.begin() + 1000);
  test::write_bytes(dir / "holed.stl", test::binary_stl(sphere));
  const auto soup = test::read_stl_soup(dir / "sphere.stl");
  const test::ExactRays rays(soup);
  const Box3 box = cell_box(soup);
  for (const auto& [file, rule] : {std::pair<std::string, std::string>{"sphere.stl", "even-odd"},
                                   {"sphere.stl", "winding-number"},
                                   {"holed.stl", "winding-number"}}) {
    const Scene scene = parse_scene(scene_json(dir / file, 1.0, box, rule), "sphere.json");
    const Occupancy o = compare(scene, rays, box, 5, file + " (" + rule + ")");
    EXPECT_EQ(o.mismatches, 0) << file << " " << rule;
    EXPECT_GT(o.inside, 3000) << file << " " << rule;
    EXPECT_GT(o.checked - o.inside, 5000) << file << " " << rule;
  }
  fs::remove_all(dir);
}

class MeshTrimReports : public ::testing::Test {
 protected:
  void SetUp() override {
    shared_ = test::shared_data_dir();
    if (shared_.empty()) GTEST_SKIP() << test::shared_data_missing_message();
    dir_ = fs::temp_directory_path() / fmt::format("trivox_mesh_trim_{}", ::getpid());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // The bunny as triangles (welded here by exact equality, as the reader does), changed by
  // `edit` and written as a binary STL.
  fs::path bunny_variant(const std::string& name, const std::function<void(test::TestMesh&)>& edit) {
    test::TestMesh m;
    std::map<std::array<double, 3>, int> index;
    for (const auto& t : test::read_stl_soup(shared_ / "meshes" / "bunny.stl")) {
      std::array<int, 3> tri;
      for (std::size_t k = 0; k < 3; ++k) {
        const auto [it, added] = index.try_emplace({t[k].x, t[k].y, t[k].z}, static_cast<int>(m.vertices.size()));
        if (added) m.vertices.push_back(t[k]);
        tri[k] = it->second;
      }
      m.triangles.push_back(tri);
    }
    edit(m);
    const fs::path p = dir_ / name;
    test::write_bytes(p, test::binary_stl(m));
    return p;
  }
  std::string refusal(const fs::path& mesh) {
    const auto soup = placed(test::read_stl_soup(shared_ / "meshes" / "bunny.stl"), 0.12);
    try {
      parse_scene(scene_json(mesh, 0.12, cell_box(soup), "even-odd"), "report.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path shared_, dir_;
};

TEST_F(MeshTrimReports, AnOpenOrFlippedMeshIsRefusedByEvenOddAndSlicedByWindingNumber) {
  const fs::path open =
      bunny_variant("open.stl", [](test::TestMesh& m) { m.triangles.erase(m.triangles.begin() + 100); });
  const fs::path flipped =
      bunny_variant("flipped.stl", [](test::TestMesh& m) { std::swap(m.triangles[7][0], m.triangles[7][1]); });
  const std::string open_report = refusal(open);
  EXPECT_NE(open_report.find("/cells/0/trim/0/shell/mesh"), std::string::npos) << open_report;
  EXPECT_NE(open_report.find("not closed: 3 open edges"), std::string::npos) << open_report;
  EXPECT_NE(open_report.find("\"inside_rule\": \"winding-number\""), std::string::npos) << open_report;
  EXPECT_NE(open_report.find("(e.g. triangle "), std::string::npos) << open_report;
  const std::string flipped_report = refusal(flipped);
  EXPECT_NE(flipped_report.find("not consistently oriented: 3 edges"), std::string::npos) << flipped_report;
  EXPECT_NE(flipped_report.find("triangle "), std::string::npos) << flipped_report;
  EXPECT_EQ(flipped_report.find("not closed"), std::string::npos) << flipped_report;

  // By the winding-number rule both slice as the closed bunny: a missing triangle subtends
  // less than half the sphere, so it moves no decision (away from its own plane).
  const auto soup = placed(test::read_stl_soup(shared_ / "meshes" / "bunny.stl"), 0.12);
  const test::ExactRays rays(soup);
  const Box3 box = cell_box(soup);
  for (const fs::path& p : {open, flipped}) {
    const Scene scene = parse_scene(scene_json(p, 0.12, box, "winding-number"), "variant.json");
    const Occupancy o = compare(scene, rays, box, 4, p.filename().string());
    EXPECT_EQ(o.mismatches, 0) << p;
    EXPECT_GT(o.inside, 1000) << p;
  }
}

}  // namespace
}  // namespace trivox
