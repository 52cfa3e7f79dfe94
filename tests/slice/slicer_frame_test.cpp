// The frame a slicer lays out (Slicer::object_bounds): a cell trimmed to the inside of a mesh
// or of another volume is framed by the box of what it keeps, not by its untrimmed volume, so
// a job starts at the part's bottom with no empty layers and reports the part's size; and no
// voxel of the part is lost to the tighter frame.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "mesh/mesh_fixtures.h"
#include "scene/scene_test_util.h"
#include "trivox/job/printed_extent.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

// A 4 mm cube cell with the given trim clauses (JSON), on the paper's J750 (600 x 300 dpi,
// 30 um layers).
std::string cube_scene(const std::string& trim) {
  return R"({"version": 1, "units": "mm", "printer": "j750-paper", "materials": ["VeroCyan", "VeroMagenta"],
  "volumes": [{"name": "slab", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[-1, -1, 1.5], [5, -1, 1.5], [-1, 5, 1.5], [5, 5, 1.5], [-1, -1, 2.5], [5, -1, 2.5], [-1, 5, 2.5],
               [5, 5, 2.5]]}}],
  "cells": [{"name": "c", "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0], [0, 0, 4], [4, 0, 4], [0, 4, 4], [4, 4, 4]]},
    "material": "VeroCyan", "trim": [)" +
         trim + "]}]}";
}

// The voxels with a material over every layer of the slicer's layout.
PrintedExtent printed(const Slicer& slicer) {
  PrintedExtent all;
  for (int layer = 0; layer < slicer.layout().num_layers; ++layer)
    all.add(printed_extent(slicer.slice_layer(layer).labels, layer));
  return all;
}

// Within one pitch of `expected` on every side: the part reaches the box (no voxel lost) and
// the frame holds nothing more.
void expect_printed_box_near(const Slicer& slicer, const Box3& expected) {
  const SliceLayout& L = slicer.layout();
  const PrintedExtent e = printed(slicer);
  ASSERT_FALSE(e.empty());
  const Box3 box = printed_box_mm(e, L);
  const Vec3 pitch{L.pitch_x_mm, L.pitch_y_mm, L.layer_mm};
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(box.lo[axis], expected.lo[axis], pitch[axis]) << "axis " << axis;
    EXPECT_NEAR(box.hi[axis], expected.hi[axis], pitch[axis]) << "axis " << axis;
  }
  // The frame's first and last layers, columns and rows hold the part.
  EXPECT_EQ(e.layer_lo, 0);
  EXPECT_EQ(e.layer_hi, L.num_layers - 1);
  EXPECT_LE(e.col_lo, 1);
  EXPECT_GE(e.col_hi, L.width_px - 2);
  EXPECT_LE(e.row_lo, 1);
  EXPECT_GE(e.row_hi, L.height_px - 2);
}

TEST(SlicerFrame, ACellInsideAMeshIsFramedByTheMeshesBox) {
  const fs::path dir = test::scratch_dir();
  test::write_bytes(dir / "inner.stl", test::binary_stl(test::box_mesh({1, 0.5, 1.25}, {2.5, 3, 3.125})));
  const Scene scene = parse_scene(cube_scene(R"({"side": "inside", "shell": {"mesh": "inner.stl"}})"), dir / "s.json");
  const Slicer slicer(scene, {});
  EXPECT_EQ(slicer.object_bounds().lo, (Vec3{1, 0.5, 1.25}));
  EXPECT_EQ(slicer.object_bounds().hi, (Vec3{2.5, 3, 3.125}));
  EXPECT_EQ(scene.bounds().size(), (Vec3{4, 4, 4}));  // the control points' box is the cube's
  EXPECT_EQ(slicer.layout().num_layers, 63);          // ceil((1.875 mm + a quarter pitch each end) / 30 um)
  expect_printed_box_near(slicer, slicer.object_bounds());

  // The reference frame, from the volume alone (SliceParams::frame_from_trims off): twice the
  // layers, the same part within a pitch on every side.
  SliceParams loose_params;
  loose_params.frame_from_trims = false;
  const Slicer loose(scene, loose_params);
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(loose.object_bounds().size()[axis], 4, 1e-9);
  EXPECT_GT(loose.layout().num_layers, 2 * slicer.layout().num_layers);
  const Box3 tight_box = printed_box_mm(printed(slicer), slicer.layout());
  const Box3 loose_box = printed_box_mm(printed(loose), loose.layout());
  const SliceLayout& L = slicer.layout();
  const Vec3 pitch{L.pitch_x_mm, L.pitch_y_mm, L.layer_mm};
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(tight_box.lo[axis], loose_box.lo[axis], pitch[axis]) << "axis " << axis;
    EXPECT_NEAR(tight_box.hi[axis], loose_box.hi[axis], pitch[axis]) << "axis " << axis;
  }
}

// Trimmed to the inside of another volume (a slab across the cube), or cut down by two clauses.
TEST(SlicerFrame, ACellInsideAVolumeOrSeveralTrimsIsFramedByWhatAllOfThemKeep) {
  const fs::path dir = test::scratch_dir();
  test::write_bytes(dir / "inner.stl", test::binary_stl(test::box_mesh({1, 0.5, 1.25}, {2.5, 3, 3.125})));
  const Scene by_volume = parse_scene(cube_scene(R"({"side": "inside", "volume": "slab"})"), dir / "v.json");
  const Slicer slab(by_volume, {});
  EXPECT_NEAR(slab.object_bounds().lo.z, 1.5, 1e-6);
  EXPECT_NEAR(slab.object_bounds().hi.z, 2.5, 1e-6);
  EXPECT_NEAR(slab.object_bounds().lo.x, 0, 1e-6);  // the cube's sides
  EXPECT_NEAR(slab.object_bounds().hi.y, 4, 1e-6);
  expect_printed_box_near(slab, slab.object_bounds());

  const Scene both = parse_scene(
      cube_scene(R"({"side": "inside", "volume": "slab"}, {"side": "inside", "shell": {"mesh": "inner.stl"}})"),
      dir / "b.json");
  const Slicer cut(both, {});
  EXPECT_NEAR(cut.object_bounds().lo.z, 1.5, 1e-6);
  EXPECT_NEAR(cut.object_bounds().hi.z, 2.5, 1e-6);
  EXPECT_EQ(cut.object_bounds().lo.x, 1);
  EXPECT_EQ(cut.object_bounds().hi.y, 3);

  // A mesh decided by its winding number bounds nothing either (with gaps, its inside may
  // reach beyond its vertices), nor does an "outside" clause: the cube's frame stays.
  const Scene winding =
      parse_scene(cube_scene(R"({"side": "inside", "shell": {"mesh": "inner.stl", "inside_rule": "winding-number"}})"),
                  dir / "w.json");
  const Slicer by_winding(winding, {});
  EXPECT_NEAR(by_winding.object_bounds().lo.x, 0, 1e-6);
  EXPECT_NEAR(by_winding.object_bounds().hi.z, 4, 1e-6);
  const Scene outside =
      parse_scene(cube_scene(R"({"side": "outside", "shell": {"mesh": "inner.stl"}})"), dir / "o.json");
  const Slicer hollow(outside, {});
  EXPECT_NEAR(hollow.object_bounds().lo.z, 0, 1e-6);
  EXPECT_NEAR(hollow.object_bounds().hi.z, 4, 1e-6);
}

}  // namespace
}  // namespace trivox
