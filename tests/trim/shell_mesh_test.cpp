// The watertight shell mesh and its point-in-solid test.
#include <random>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trim/trim_fixtures.h"
#include "trivox/io/model.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {
namespace {

using test::Hexahedron;

const Hexahedron kSkewed = {Vec3{0, 0, 0},     Vec3{4, 0.5, 0.2},   Vec3{-0.5, 3, 0.3},  Vec3{3.5, 3.5, -0.2},
                            Vec3{0.3, 0.2, 5}, Vec3{4.2, 0.4, 4.6}, Vec3{0.1, 3.3, 5.2}, Vec3{3.9, 3.6, 5.5}};

TEST(ShellMesh, SixFacesOfAHexahedronAreClosed) {
  const ShellMesh mesh(test::hexahedron_shell(kSkewed), 1e-3);
  EXPECT_EQ(mesh.open_edges(), 0u);
  EXPECT_GT(mesh.triangle_count(), 12u);
  // Welded: the shared edges and corners hold one vertex each, n*n*6 samples minus the seams.
  const auto n = static_cast<std::size_t>(mesh.samples());
  EXPECT_EQ(mesh.vertex_count(), 6 * (n - 2) * (n - 2) + 12 * (n - 2) + 8);
}

TEST(ShellMesh, AMissingFaceLeavesOpenEdges) {
  const ShellMesh mesh(test::hexahedron_shell(kSkewed, 3), 1e-3);
  EXPECT_GT(mesh.open_edges(), 0u);
}

TEST(ShellMesh, ContainsAgreesWithTheWindingNumberOfAFinerSoup) {
  const TrimShell shell = test::hexahedron_shell(kSkewed);
  const ShellMesh mesh(shell, 1e-4);
  const test::TriangleSoup soup(shell, 2 * mesh.samples());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-1, 5), uy(-1, 4.5), uz(-1, 6.5);
  int inside = 0, outside = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{ux(rng), uy(rng), uz(rng)};
    const double w = soup.winding(p);
    if (std::abs(std::abs(w) - 0.5) < 0.45) continue;  // within a hair of the surface
    const bool expected = std::abs(w) > 0.5;
    EXPECT_EQ(mesh.contains(p), expected) << p.x << " " << p.y << " " << p.z << " winding " << w;
    (expected ? inside : outside)++;
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 300);
}

TEST(ShellMesh, DegeneratePositionsOnVerticesAndEdgesCountOnce) {
  // An axis-aligned box: points in the planes of its faces and on the lines of its edges
  // hit the mesh's vertices and edges exactly. The tie rule ("at or above counts as above")
  // makes the box half-open, (0, 2] in y and z, and never counts a crossing twice.
  const ShellMesh mesh(test::hexahedron_shell(test::axis_box({0, 0, 0}, {2, 2, 2})), 1e-3);
  for (double y : {0.0, 0.5, 1.0, 2.0})
    for (double z : {0.0, 0.5, 1.0, 2.0}) {
      const bool interior = y > 0 && y <= 2 && z > 0 && z <= 2;
      EXPECT_EQ(mesh.contains({1.0, y, z}), interior) << y << " " << z;
      EXPECT_FALSE(mesh.contains({-1.0, 1.0 + y, z + 3.0}));
    }
}

TEST(ShellMesh, DuckBrepIsClosed) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model model = read_model(dir / "surfaces" / "duck_brep.xml");
  TrimShell shell;
  shell.name = "duck_brep.xml";
  for (const Patch& p : model.patches)
    if (p.spline.param_dim() == 2) shell.surfaces.push_back(p.spline);
  ASSERT_EQ(shell.surfaces.size(), 6u);
  const ShellMesh mesh(shell, 0.01 * norm(ShellMesh(shell, 1e9).bounds().hi - ShellMesh(shell, 1e9).bounds().lo));
  EXPECT_EQ(mesh.open_edges(), 0u);
}

}  // namespace
}  // namespace trivox
