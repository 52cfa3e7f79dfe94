// The bundled chalice (examples/scenes/chalice.json): three named volumes (base and cup by
// revolution, the knot by a sweep) whose union gives five Boolean cells that print. The knot
// does not fold, its two ends are buried in the base and the cup, and on layers through every
// part each pixel's owner is the region that independent global solves in the three volumes
// give: no pixel in two cells, none of the union lost.
#include <array>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "trivox/inverse/invert.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {
namespace {

const std::filesystem::path kChalice = std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "scenes" / "chalice.json";

enum Part { kBase = 0, kKnot = 1, kCup = 2 };

// The scene cell of each region, by the set of volumes it lies in (bit 0 base, 1 knot, 2 cup).
std::array<int, 8> cells_by_region(const Scene& scene) {
  const std::array<std::string, 8> names = {"",
                                            "chalice/base",
                                            "chalice/knot",
                                            "chalice/knot in base",
                                            "chalice/cup",
                                            "chalice/base+cup",
                                            "chalice/knot in cup",
                                            "chalice/base+knot+cup"};
  std::array<int, 8> cells{};
  cells.fill(-1);
  for (std::size_t region = 1; region < names.size(); ++region)
    for (std::size_t c = 0; c < scene.cells.size(); ++c)
      if (scene.cells[c].name == names[region]) cells[region] = static_cast<int>(c);
  return cells;
}

TEST(Chalice, ThreeVolumesGiveFiveCellsThatPrintAndTwoEmptyOnes) {
  const Scene scene = read_scene(kChalice);
  ASSERT_EQ(scene.volumes.size(), 3u);
  EXPECT_EQ(scene.volumes[kBase].name, "base");
  EXPECT_EQ(scene.volumes[kKnot].name, "knot");
  EXPECT_EQ(scene.volumes[kCup].name, "cup");
  // Base and cup are exact revolutions (rational); the knot is one sweep.
  EXPECT_TRUE(scene.volumes[kBase].volume.spline().is_rational());
  EXPECT_TRUE(scene.volumes[kCup].volume.spline().is_rational());
  ASSERT_EQ(scene.cells.size(), 7u);
  const std::array<int, 8> cells = cells_by_region(scene);
  for (int region = 1; region < 8; ++region) ASSERT_GE(cells[static_cast<std::size_t>(region)], 0) << region;
  // The shared regions are parametrized by the knot.
  EXPECT_EQ(scene.cells[static_cast<std::size_t>(cells[0b011])].scene_volume, kKnot);
  EXPECT_EQ(scene.cells[static_cast<std::size_t>(cells[0b110])].scene_volume, kKnot);
  EXPECT_EQ(scene.cells[static_cast<std::size_t>(cells[0b001])].scene_volume, kBase);
  EXPECT_EQ(scene.cells[static_cast<std::size_t>(cells[0b100])].scene_volume, kCup);
  // Base and cup are apart (their control boxes already); the knot reaches into both.
  const Box3 base = scene.volumes[kBase].volume.bounds(), knot = scene.volumes[kKnot].volume.bounds(),
             cup = scene.volumes[kCup].volume.bounds();
  EXPECT_LT(base.hi.z, cup.lo.z);
  EXPECT_LT(knot.lo.z, base.hi.z);
  EXPECT_GT(knot.hi.z, cup.lo.z);
}

TEST(Chalice, KnotDoesNotFoldAndItsEndsAreBuriedInBaseAndCup) {
  const Scene scene = read_scene(kChalice);
  ASSERT_EQ(scene.volumes.size(), 3u);
  const Volume& knot = scene.volumes[kKnot].volume;
  // det J keeps one sign; it vanishes only on the four lines of the disc section's corners.
  const JacobianReport r = check_jacobian(knot, {65});
  EXPECT_NE(r.classification, JacobianClass::kFolded);
  EXPECT_EQ(std::min(r.positive, r.negative), 0);
  EXPECT_LE(r.zero, 4 * 65);
  // Every point of the end discs (w = 0 and w = 1) lies inside the base and the cup, so the
  // knot's flat ends never show.
  const GlobalSolver base(scene.volumes[kBase].volume), cup(scene.volumes[kCup].volume);
  const ParamBox d = knot.domain();
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double u = d.lo.x + (d.hi.x - d.lo.x) * i / 10, v = d.lo.y + (d.hi.y - d.lo.y) * j / 10;
      const Vec3 start = knot.evaluate({u, v, d.lo.z}), end = knot.evaluate({u, v, d.hi.z});
      EXPECT_EQ(base.solve(start).status, GlobalStatus::kUnique) << start.x << " " << start.y << " " << start.z;
      EXPECT_EQ(cup.solve(end).status, GlobalStatus::kUnique) << end.x << " " << end.y << " " << end.z;
    }
}

// Whether x is inside the volume, by a global solve (none outside its control box). Counts
// the points with several preimages: a revolution has two on its seam, the half-plane
// y = 0, x > 0 where its angles 0 and 360 degrees meet; anywhere else the volume would
// overlap itself.
struct InsideTest {
  const Volume& volume;
  GlobalSolver solver;
  std::int64_t on_seam = 0, multiple = 0;
  explicit InsideTest(const Volume& v) : volume(v), solver(v) {}
  bool operator()(Vec3 x) {
    const Box3& b = volume.bounds();
    if (x.x < b.lo.x || x.x > b.hi.x || x.y < b.lo.y || x.y > b.hi.y || x.z < b.lo.z || x.z > b.hi.z) return false;
    const GlobalResult r = solver.solve(x);
    if (r.status == GlobalStatus::kMultiple) ++(std::abs(x.y) < 1e-9 && x.x > 0 ? on_seam : multiple);
    return !r.preimages.empty();
  }
};

TEST(Chalice, CellsPartitionTheUnionOfBaseKnotAndCupPixelByPixel) {
  const Scene scene = read_scene(kChalice);
  ASSERT_EQ(scene.volumes.size(), 3u);
  const std::array<int, 8> cells = cells_by_region(scene);
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  std::array<InsideTest, 3> inside = {InsideTest(scene.volumes[kBase].volume), InsideTest(scene.volumes[kKnot].volume),
                                      InsideTest(scene.volumes[kCup].volume)};
  auto region_of = [&](Vec3 x) {
    int region = 0;
    for (int p = 0; p < 3; ++p) region |= inside[static_cast<std::size_t>(p)](x) ? 1 << p : 0;
    return region;
  };
  std::array<std::int64_t, 8> per_region{};
  std::int64_t mismatches = 0, borderline = 0;
  // z (mm): the knot's start in the base; its lowest loops in the base; the five passes of the
  // stem; its highest loops in the cup's bottom; its end in the cup; the cup's wall.
  for (double z : {1.5, 2.5, 7.5, 11.8, 13.0, 20.0}) {
    const int layer = static_cast<int>(std::lround((z - L.z0_mm) / L.layer_mm - 0.5));
    const double zl = L.z_of_layer(layer);
    std::vector<int> owner;
    const LayerResult result = slicer.slice_layer(layer, {.owner = true});
    owner = result.owner;
    EXPECT_EQ(result.stats.unresolved_pixels, 0) << "layer " << layer;
    EXPECT_EQ(result.stats.folded_pixels, 0) << "layer " << layer;
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const Vec3 x{L.x_of_col(col), L.y_of_row(row), zl};
        const int region = region_of(x);
        const int expected = region ? cells[static_cast<std::size_t>(region)] : -1;
        const int o =
            owner[static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(col)];
        ++per_region[static_cast<std::size_t>(region)];
        if (o == expected) continue;
        // A centre within a hair (1e-5 mm) of a face may fall either way: the slicer's and the
        // solver's residual tolerances differ.
        bool near_face = false;
        for (const Vec3 d : {Vec3{1e-5, 0, 0}, Vec3{-1e-5, 0, 0}, Vec3{0, 1e-5, 0}, Vec3{0, -1e-5, 0}})
          near_face = near_face || region_of(x + d) != region;
        (near_face ? borderline : mismatches)++;
        EXPECT_TRUE(near_face) << "pixel " << col << ", " << row << " of layer " << layer << " (" << x.x << ", " << x.y
                               << ", " << x.z << "): owner " << o << ", expected cell " << expected << " (region "
                               << region << ")";
      }
  }
  std::cout << "chalice pixels per region (base, knot, knot in base, cup, base+cup, knot in cup, all three):";
  for (std::size_t region = 1; region < 8; ++region) std::cout << " " << per_region[region];
  std::cout << "; " << borderline
            << " within 1e-5 mm of a face; points on the seams of base and cup: " << inside[kBase].on_seam << ", "
            << inside[kCup].on_seam << "\n";
  EXPECT_EQ(mismatches, 0);
  EXPECT_LE(borderline, 6);
  // No volume overlaps itself (the knot has no seam; base and cup only theirs, which the
  // middle pixel row of this layout lies on).
  for (const InsideTest& t : inside) EXPECT_EQ(t.multiple, 0);
  EXPECT_EQ(inside[kKnot].on_seam, 0);
  // Every region that prints is on these layers.
  for (int region : {0b001, 0b010, 0b011, 0b100, 0b110})
    EXPECT_GT(per_region[static_cast<std::size_t>(region)], 1000) << region;
  EXPECT_EQ(per_region[0b101], 0);
  EXPECT_EQ(per_region[0b111], 0);
}

}  // namespace
}  // namespace trivox
