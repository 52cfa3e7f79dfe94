// Trimmed cells in the slicer: Boolean cells partition their union, shell and parametric
// trims agree with independent inside tests and narrow the inverted pixels without changing
// one, and every inside pixel has one owner.
#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "slice/slice_fixtures.h"
#include "support/test_support.h"
#include "trim/trim_fixtures.h"
#include "trivox/inverse/invert.h"
#include "trivox/io/model.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

using test::Hexahedron;

Cell region(const std::string& name, int scene_volume, const Scene& s, int material, std::vector<TrimClause> clauses) {
  Cell c =
      test::constant_cell(s.volumes[static_cast<std::size_t>(scene_volume)].volume, material, s.num_materials(), name);
  c.scene_volume = scene_volume;
  c.trim.clauses = std::move(clauses);
  return c;
}

TrimClause volume_clause(int v, TrimSide side) {
  TrimClause k;
  k.kind = TrimKind::kVolume;
  k.volume = v;
  k.side = side;
  return k;
}

// Clauses of `kind` that keep what lies inside `keep` and outside `hole`.
std::vector<TrimClause> keep_with_hole(TrimKind kind, const Hexahedron& keep, const Hexahedron& hole) {
  TrimClause inside;
  inside.kind = kind;
  inside.side = TrimSide::kInside;
  inside.shell = std::make_shared<TrimShell>(test::hexahedron_shell(keep));
  TrimClause outside = inside;
  outside.side = TrimSide::kOutside;
  outside.shell = std::make_shared<TrimShell>(test::hexahedron_shell(hole));
  return {inside, outside};
}

// Two overlapping volumes: an axis-aligned box and a skewed hexahedron.
Scene boolean_scene(bool reversed) {
  Scene s = test::scene_with({}, 3);
  s.volumes.push_back({"A", "/volumes/0", test::hexahedron_volume(test::axis_box({0, 0, 0}, {3, 2, 1}))});
  const Hexahedron b = {Vec3{1.6, 0.7, -0.3}, Vec3{4.1, 0.9, -0.2}, Vec3{1.4, 2.8, -0.25}, Vec3{4.0, 3.1, -0.35},
                        Vec3{1.8, 0.6, 1.3},  Vec3{4.3, 0.8, 1.25}, Vec3{1.5, 2.9, 1.4},   Vec3{4.2, 3.0, 1.2}};
  s.volumes.push_back({"B", "/volumes/1", test::hexahedron_volume(b)});
  std::vector<Cell> cells;
  cells.push_back(region("A only", 0, s, 0, {volume_clause(1, TrimSide::kOutside)}));
  cells.push_back(region("B only", 1, s, 1, {volume_clause(0, TrimSide::kOutside)}));
  cells.push_back(region("A and B", 1, s, 2, {volume_clause(0, TrimSide::kInside)}));
  if (reversed) std::reverse(cells.begin(), cells.end());
  s.cells = std::move(cells);
  return s;
}

bool inside_by_global_solve(const GlobalSolver& solver, Vec3 x) {
  const GlobalResult r = solver.solve(x);
  return !r.preimages.empty();
}

TEST(TrimmedCells, BooleanCellsPartitionTheUnion) {
  const Scene scene = boolean_scene(false);
  const Scene reversed = boolean_scene(true);
  const Slicer slicer(scene, {});
  const Slicer slicer_reversed(reversed, {});
  const SliceLayout& L = slicer.layout();
  ASSERT_EQ(L.width_px, slicer_reversed.layout().width_px);
  const GlobalSolver solve_a(scene.volumes[0].volume), solve_b(scene.volumes[1].volume);
  std::array<std::int64_t, 3> owned{0, 0, 0};
  int mismatches = 0, borderline = 0;
  for (int layer : {2, L.num_layers / 3, L.num_layers / 2, L.num_layers - 3}) {
    std::vector<int> owner, owner_reversed;
    const LayerResult r = slicer.slice_layer(layer, {.owner = true});
    owner = r.owner;
    owner_reversed = slicer_reversed.slice_layer(layer, {.owner = true}).owner;
    std::int64_t sum = 0;
    for (auto n : r.stats.pixels_per_cell) sum += n;
    EXPECT_EQ(sum, r.stats.pixels_inside);
    const double z = L.z_of_layer(layer);
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const std::size_t at =
            static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(col);
        const int o = owner[at];
        // No pixel in two cells: had two regions overlapped, reversing the cells' order would
        // hand the overlap to the other one.
        EXPECT_EQ(owner_reversed[at], o < 0 ? -1 : 2 - o) << layer << " " << row << " " << col;
        const Vec3 x{L.x_of_col(col), L.y_of_row(row), z};
        const bool in_a = inside_by_global_solve(solve_a, x), in_b = inside_by_global_solve(solve_b, x);
        const int expected = in_a && in_b ? 2 : in_a ? 0 : in_b ? 1 : -1;
        if (o >= 0) ++owned[static_cast<std::size_t>(o)];
        if (o == expected) continue;
        // None lost, none misplaced, except a centre within a hair (1e-5 mm) of a face, where
        // the two inverse tolerances may differ.
        bool near_face = false;
        for (const Vec3 d : {Vec3{1e-5, 0, 0}, Vec3{-1e-5, 0, 0}, Vec3{0, 1e-5, 0}, Vec3{0, -1e-5, 0}})
          near_face = near_face || inside_by_global_solve(solve_a, x + d) != in_a ||
                      inside_by_global_solve(solve_b, x + d) != in_b;
        (near_face ? borderline : mismatches)++;
        EXPECT_TRUE(near_face) << "pixel " << col << ", " << row << " of layer " << layer << " (" << x.x << ", " << x.y
                               << ", " << x.z << "): owner " << o << ", expected " << expected;
      }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_LE(borderline, 4);
  for (auto n : owned) EXPECT_GT(n, 100);
}

TEST(TrimmedCells, ShellTrimAgreesWithAFinerPointInSolidTestAwayFromTheSurface) {
  const Hexahedron shell_corners = {Vec3{0.8, 0.5, -0.4}, Vec3{3.6, 0.2, -0.3}, Vec3{1.0, 2.6, -0.2},
                                    Vec3{3.4, 2.3, -0.5}, Vec3{0.6, 0.6, 0.7},  Vec3{3.9, 0.4, 0.8},
                                    Vec3{0.9, 2.2, 0.9},  Vec3{3.7, 2.5, 0.6}};
  auto shell = std::make_shared<TrimShell>(test::hexahedron_shell(shell_corners));
  Scene s = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {3, 2, 1}), 0, 2, "inside")}, 2);
  TrimClause k;
  k.kind = TrimKind::kShell;
  k.side = TrimSide::kInside;
  k.shell = shell;
  s.cells[0].trim.clauses.push_back(k);
  const Slicer slicer(s, {});
  const SliceLayout& L = slicer.layout();
  const test::TriangleSoup soup(*shell, 64);
  int checked = 0, inside = 0;
  for (int layer : {3, L.num_layers / 2, L.num_layers - 4}) {
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    const double z = L.z_of_layer(layer);
    for (int row = 1; row < L.height_px; row += 3)
      for (int col = 1; col < L.width_px; col += 5) {
        const Vec3 x{L.x_of_col(col), L.y_of_row(row), z};
        // Away from the surface: the pixel and its six neighbours one pitch away agree.
        const bool in = soup.inside(x);
        bool near = false;
        for (const Vec3 d : {Vec3{L.pitch_x_mm, 0, 0}, Vec3{-L.pitch_x_mm, 0, 0}, Vec3{0, L.pitch_y_mm, 0},
                             Vec3{0, -L.pitch_y_mm, 0}, Vec3{0, 0, L.layer_mm}, Vec3{0, 0, -L.layer_mm}})
          near = near || soup.inside(x + d) != in;
        const bool in_box = x.x > 0.05 && x.x < 2.95 && x.y > 0.05 && x.y < 1.95 && x.z > 0.05 && x.z < 0.95;
        const bool out_box = x.x < -0.05 || x.x > 3.05 || x.y < -0.05 || x.y > 2.05;
        if (near || !(in_box || out_box)) continue;
        ++checked;
        const bool expected = in && in_box;
        inside += expected;
        EXPECT_EQ(owner[static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) +
                        static_cast<std::size_t>(col)] == 0,
                  expected)
            << x.x << " " << x.y << " " << x.z;
      }
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(checked - inside, 20);
}

TEST(TrimmedCells, ParametricTrimAgreesWithDirectEvaluation) {
  // The box maps (u, v, w) in [0,1]^3 to (3u, 2v, w); the trim removes the parameter box
  // [0.2, 0.7] x [0.1, 0.6] x [0.3, 0.9].
  auto shell = std::make_shared<TrimShell>(test::hexahedron_shell(test::axis_box({0.2, 0.1, 0.3}, {0.7, 0.6, 0.9})));
  Scene s = test::scene_with({test::constant_cell(test::box_volume({0, 0, 0}, {3, 2, 1}), 1, 2, "hollow")}, 2);
  TrimClause k;
  k.kind = TrimKind::kParametric;
  k.side = TrimSide::kOutside;
  k.shell = shell;
  s.cells[0].trim.clauses.push_back(k);
  const Slicer slicer(s, {});
  const SliceLayout& L = slicer.layout();
  int removed = 0, kept = 0;
  for (int layer : {L.num_layers / 4, L.num_layers / 2}) {
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    for (int row = 0; row < L.height_px; ++row)
      for (int col = 0; col < L.width_px; ++col) {
        const Vec3 uvw{L.x_of_col(col) / 3, L.y_of_row(row) / 2, L.z_of_layer(layer)};
        const bool in_cell = uvw.x > 1e-9 && uvw.x < 1 - 1e-9 && uvw.y > 1e-9 && uvw.y < 1 - 1e-9;
        auto strictly = [](double t, double lo, double hi) { return t > lo + 1e-9 && t < hi - 1e-9; };
        auto closed = [](double t, double lo, double hi) { return t >= lo - 1e-9 && t <= hi + 1e-9; };
        const bool in_trim = strictly(uvw.x, 0.2, 0.7) && strictly(uvw.y, 0.1, 0.6) && strictly(uvw.z, 0.3, 0.9);
        const bool out_trim = !(closed(uvw.x, 0.2, 0.7) && closed(uvw.y, 0.1, 0.6) && closed(uvw.z, 0.3, 0.9));
        if (!in_cell || !(in_trim || out_trim)) continue;  // on a face: either answer is exact
        const bool owned = owner[static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) +
                                 static_cast<std::size_t>(col)] == 0;
        EXPECT_EQ(owned, out_trim) << uvw.x << " " << uvw.y << " " << uvw.z;
        (out_trim ? kept : removed)++;
      }
  }
  EXPECT_GT(removed, 300);
  EXPECT_GT(kept, 1000);
}

// "Inside" parametric trims narrow the inverted pixels to their outline (the parametric
// tessellation mapped through the cell's curved volume, widened by the outline margin)
// without losing a pixel: the owners and labels equal those of a run that inverts every pixel
// of the cell's outline and tests each one, on every layer.
TEST(TrimmedCells, ParametricOutlinesNarrowTheCandidatesAndChangeNoPixel) {
  // A rational quarter annulus; the kept region is a skewed parameter hexahedron that reaches
  // past the domain's face v = 0 (its outline there follows the cell's face), with a smaller
  // one removed from it.
  const Hexahedron keep = {Vec3{0.15, -0.2, 0.1},  Vec3{0.85, -0.1, 0.15}, Vec3{0.2, 0.7, 0.05},
                           Vec3{0.9, 0.6, 0.2},    Vec3{0.1, -0.15, 0.8},  Vec3{0.8, -0.2, 0.9},
                           Vec3{0.25, 0.65, 0.95}, Vec3{0.95, 0.75, 0.85}};
  Scene s = test::scene_with({test::gradient_cell(test::annulus_sector(1, 3, 1))}, 2);
  s.cells[0].trim.clauses =
      keep_with_hole(TrimKind::kParametric, keep, test::axis_box({0.4, 0.2, 0.3}, {0.6, 0.4, 0.6}));
  SliceParams reference_params;
  reference_params.parametric_outlines = false;
  const Slicer narrowed(s, {}), reference(s, reference_params);
  const SliceLayout& L = narrowed.layout();
  ASSERT_EQ(L.num_layers, reference.layout().num_layers);
  std::int64_t candidates = 0, reference_candidates = 0, inside_pixels = 0;
  for (int layer = 0; layer < L.num_layers; layer += 2) {
    std::vector<int> owner, reference_owner;
    const LayerResult r = narrowed.slice_layer(layer, {.owner = true});
    owner = r.owner;
    const LayerResult ref = reference.slice_layer(layer, {.owner = true});
    reference_owner = ref.owner;
    EXPECT_EQ(owner, reference_owner) << "layer " << layer;
    EXPECT_TRUE(std::ranges::equal(r.labels.values(), ref.labels.values())) << "layer " << layer;
    EXPECT_EQ(r.stats.pixels_inside, ref.stats.pixels_inside) << "layer " << layer;
    candidates += r.stats.candidates;
    reference_candidates += ref.stats.candidates;
    inside_pixels += r.stats.pixels_inside;
  }
  std::cout << "parametric outlines: " << candidates << " candidates instead of " << reference_candidates << " for "
            << inside_pixels << " inside pixels\n";
  EXPECT_GT(inside_pixels, 1000);
  EXPECT_LT(candidates, reference_candidates);
  EXPECT_LT(static_cast<double>(candidates), 0.8 * static_cast<double>(reference_candidates));
}

// Shell trims narrow the inverted pixels to those inside the shell's cut by the layer (an
// "outside" shell to those outside it) without changing a pixel: owners and labels equal
// those of a run that inverts every pixel of the cell's outline and tests each one, and that
// run inverts exactly the pixels of the untrimmed cell.
TEST(TrimmedCells, ShellTrimsNarrowTheCandidatesAndChangeNoPixel) {
  // A rational quarter annulus with a gradient, kept inside a skewed hexahedron that cuts
  // away its ends and its top, without a box-shaped hole.
  const Hexahedron keep = {Vec3{0.4, -0.3, -0.2}, Vec3{2.6, -0.2, -0.3}, Vec3{0.2, 2.4, -0.25}, Vec3{2.4, 2.2, -0.1},
                           Vec3{0.5, -0.2, 0.8},  Vec3{2.7, -0.3, 0.7},  Vec3{0.3, 2.3, 0.75},  Vec3{2.5, 2.5, 0.85}};
  const Scene untrimmed = test::scene_with({test::gradient_cell(test::annulus_sector(1, 3, 1))}, 2);
  Scene s = untrimmed;
  s.cells[0].trim.clauses = keep_with_hole(TrimKind::kShell, keep, test::axis_box({1.2, 0.8, 0.2}, {1.8, 1.4, 0.6}));
  // One frame for the three: the untrimmed volume's (a tight frame would differ from the
  // whole cell's; slicer_frame_test.cpp checks it).
  SliceParams params;
  params.frame_from_trims = false;
  SliceParams reference_params = params;
  reference_params.model_space_narrowing = false;
  const Slicer narrowed(s, params), reference(s, reference_params), whole(untrimmed, params);
  const SliceLayout& L = narrowed.layout();
  ASSERT_EQ(L.num_layers, reference.layout().num_layers);
  ASSERT_EQ(L.num_layers, whole.layout().num_layers);
  std::int64_t candidates = 0, reference_candidates = 0, whole_candidates = 0, inside_pixels = 0, whole_inside = 0;
  for (int layer = 0; layer < L.num_layers; layer += 3) {
    std::vector<int> owner, reference_owner;
    const LayerResult r = narrowed.slice_layer(layer, {.owner = true});
    owner = r.owner;
    const LayerResult ref = reference.slice_layer(layer, {.owner = true});
    reference_owner = ref.owner;
    const LayerResult w = whole.slice_layer(layer);
    EXPECT_EQ(owner, reference_owner) << "layer " << layer;
    EXPECT_TRUE(std::ranges::equal(r.labels.values(), ref.labels.values())) << "layer " << layer;
    EXPECT_EQ(r.stats.pixels_inside, ref.stats.pixels_inside) << "layer " << layer;
    EXPECT_EQ(ref.stats.candidates, w.stats.candidates) << "layer " << layer;
    EXPECT_LE(r.stats.candidates, ref.stats.candidates) << "layer " << layer;
    candidates += r.stats.candidates;
    reference_candidates += ref.stats.candidates;
    whole_candidates += w.stats.candidates;
    inside_pixels += r.stats.pixels_inside;
    whole_inside += w.stats.pixels_inside;
  }
  std::cout << "shell trims: " << candidates << " candidates instead of " << reference_candidates << " for "
            << inside_pixels << " inside pixels (untrimmed cell: " << whole_candidates << " candidates, "
            << whole_inside << " inside)\n";
  EXPECT_GT(inside_pixels, 1000);
  EXPECT_LT(inside_pixels, whole_inside);
  EXPECT_LT(static_cast<double>(candidates), 0.8 * static_cast<double>(reference_candidates));
}

// Every pixel inside some patch of a multi-patch model is owned by exactly one cell: the last
// in scene order that contains it, as an independent global solve per patch finds.
void expect_owners_of_multipatch(const std::vector<Volume>& patches) {
  std::vector<Cell> cells;
  for (std::size_t i = 0; i < patches.size(); ++i)
    cells.push_back(test::constant_cell(patches[i], static_cast<int>(i % 3), 3, "patch " + std::to_string(i)));
  const Scene s = test::scene_with(std::move(cells), 3);
  const Slicer slicer(s, {});
  const SliceLayout& L = slicer.layout();
  std::vector<GlobalSolver> solvers;
  for (const Cell& c : s.cells) solvers.emplace_back(c.volume);
  std::vector<std::int64_t> per_cell(patches.size(), 0);
  int mismatches = 0, borderline = 0;
  for (int layer : {L.num_layers / 3, (2 * L.num_layers) / 3}) {
    std::vector<int> owner;
    const LayerResult r = slicer.slice_layer(layer, {.owner = true});
    owner = r.owner;
    std::int64_t owned = 0;
    for (std::size_t i = 0; i < patches.size(); ++i) {
      per_cell[i] += r.stats.pixels_per_cell[i];
      owned += r.stats.pixels_per_cell[i];
    }
    EXPECT_EQ(owned, r.stats.pixels_inside);
    for (int row = 0; row < L.height_px; row += 2)
      for (int col = 0; col < L.width_px; col += 2) {
        const Vec3 x{L.x_of_col(col), L.y_of_row(row), L.z_of_layer(layer)};
        auto last_containing = [&](Vec3 p) {
          for (int c = static_cast<int>(solvers.size()) - 1; c >= 0; --c)
            if (inside_by_global_solve(solvers[static_cast<std::size_t>(c)], p)) return c;
          return -1;
        };
        const int expected = last_containing(x);
        const int o =
            owner[static_cast<std::size_t>(row) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(col)];
        if (o == expected) continue;
        const double h = 1e-5;
        bool near_face = false;
        for (const Vec3 d : {Vec3{h, 0, 0}, Vec3{-h, 0, 0}, Vec3{0, h, 0}, Vec3{0, -h, 0}})
          near_face = near_face || last_containing(x + d) != expected;
        (near_face ? borderline : mismatches)++;
      }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_LE(borderline, 8);
  for (std::int64_t n : per_cell) EXPECT_GT(n, 0);
}

TEST(TrimmedCells, TwoTouchingBoxesShareTheirFaceWithOneOwner) {
  // The face x = 1.5 lies on pixel centres' columns for no pitch in particular; the boxes
  // overlap by nothing, so every pixel on the face is the second box's.
  expect_owners_of_multipatch({test::box_volume({0, 0, 0}, {1.5, 1, 1}), test::box_volume({1.5, 0, 0}, {3, 1, 1})});
}

TEST(TrimmedCells, MultiPatchModelFromSharedDataHasOneOwnerPerPixel) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Model model = read_model(dir / "volumes" / "gismo" / "four_cubes_bspline.xml");
  std::vector<Volume> patches;
  for (int i : model.volume_indices()) {
    // Scaled to 3 mm so a layer holds a few thousand pixels.
    const TensorSpline& sp = model.patches[static_cast<std::size_t>(i)].spline;
    patches.emplace_back(sp.transformed([](std::span<double> p) {
      for (double& c : p) c *= 1.5;
    }));
  }
  ASSERT_GE(patches.size(), 2u);
  expect_owners_of_multipatch(patches);
}

}  // namespace
}  // namespace trivox
