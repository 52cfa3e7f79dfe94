// The box of examples/shared_scenes/teapot_trimmed_box.json trimmed by the IRIT trimmed-surface model
// of the Utah teapot (../shared): its shell has hairline gaps along the seams, and the slicer
// decides it by the gap-tolerant vote. Checked against vertical rays through an independent
// tessellation: each surface's grid at a finer sampling, a triangle kept when its centroid
// lies inside the surface's trimming loops (no clipping), so it differs from the slicer's
// near the seams, where vertical lines crossed an odd number of times are skipped.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trim/trim_fixtures.h"
#include "trivox/io/model.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox {
namespace {

bool in_loops(const std::vector<std::vector<std::array<double, 2>>>& loops, double u, double v) {
  bool in = false;
  for (const auto& poly : loops)
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
      const auto& a = poly[i];
      const auto& b = poly[j];
      if ((a[1] >= v) != (b[1] >= v) && u < a[0] + (v - a[1]) / (b[1] - a[1]) * (b[0] - a[0])) in = !in;
    }
  return in;
}

// The teapot as the scene places it: scale 5, then 90 degrees about x, (x, y, z) -> (5x, -5z, 5y).
std::vector<std::array<Vec3, 3>> teapot_soup(const Model& model, int n) {
  std::vector<std::array<Vec3, 3>> out;
  const TrimmedModel& m = model.trimmed_models.at(0);
  for (std::size_t i = 0; i < m.surfaces.size(); ++i) {
    const TensorSpline& s = model.patches[static_cast<std::size_t>(m.surfaces[i].patch)].spline;
    std::vector<std::vector<std::array<double, 2>>> loops;
    for (const auto& loop : m.surfaces[i].loops) {
      std::vector<std::array<double, 2>> poly;
      for (int ref : loop) {
        const auto& seg = m.segments[static_cast<std::size_t>(std::abs(ref) - 1)];
        const std::size_t side = seg.surfaces[0] == static_cast<int>(i) ? 0 : 1;
        const TensorSpline& c = seg.curves[side];
        EXPECT_EQ(c.knots(0).order(), 2);  // polylines: the control points are the curve
        std::vector<std::array<double, 2>> pts;
        for (int k = 0; k < c.num_ctrl(0); ++k) pts.push_back({c.point(k)[0], c.point(k)[1]});
        if (ref < 0) std::reverse(pts.begin(), pts.end());
        poly.insert(poly.end(), pts.begin(), pts.end());
      }
      loops.push_back(std::move(poly));
    }
    auto at = [&](double u, double v) {
      const double t[2] = {u, v};
      double p[3];
      s.evaluate(t, p);
      return Vec3{5 * p[0], -5 * p[2], 5 * p[1]};
    };
    const double u0 = s.lo(0), u1 = s.hi(0), v0 = s.lo(1), v1 = s.hi(1);
    for (int j = 0; j + 1 < n; ++j)
      for (int k = 0; k + 1 < n; ++k) {
        const double ua = u0 + (u1 - u0) * k / (n - 1), ub = u0 + (u1 - u0) * (k + 1) / (n - 1);
        const double va = v0 + (v1 - v0) * j / (n - 1), vb = v0 + (v1 - v0) * (j + 1) / (n - 1);
        if (in_loops(loops, (2 * ua + ub) / 3, (va + 2 * vb) / 3)) out.push_back({at(ua, va), at(ub, vb), at(ua, vb)});
        if (in_loops(loops, (ua + 2 * ub) / 3, (2 * va + vb) / 3)) out.push_back({at(ua, va), at(ub, va), at(ub, vb)});
      }
  }
  return out;
}

TEST(TeapotTrimmedBox, GapTolerantShellAgreesWithVerticalRaysAwayFromSurfaceAndSeams) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const Scene scene =
      read_scene(std::filesystem::path(TRIVOX_EXAMPLES_DIR) / "shared_scenes" / "teapot_trimmed_box.json");
  const Slicer slicer(scene, {});
  // The seams close within the allowed gap (1e-3 of the size).
  const ShellMesh mesh(*scene.cells.at(0).trim.clauses.at(0).shell, 0.01);
  EXPECT_TRUE(mesh.gap_tolerant());
  const double size = norm(mesh.bounds().hi - mesh.bounds().lo);
  std::cout << "teapot shell: " << mesh.triangle_count() << " triangles, seams within " << mesh.seam_gap() << " mm ("
            << mesh.seam_gap() / size << " of its size)\n";
  EXPECT_GT(mesh.seam_gap(), 0.0);  // the trimming curves are fitted, so the seams do not meet exactly
  EXPECT_LT(mesh.seam_gap(), 5e-4 * size);
  const SliceLayout& L = slicer.layout();
  const Model model = read_model(dir / "surfaces" / "teapot_trimmed_model.itd");
  const test::VerticalRays rays(teapot_soup(model, 400));

  const auto width = static_cast<std::size_t>(L.width_px);
  std::vector<std::vector<double>> columns(width * static_cast<std::size_t>(L.height_px));
  std::vector<std::uint8_t> odd(columns.size(), 0);
  std::int64_t odd_columns = 0;
  for (int row = 0; row < L.height_px; ++row)
    for (int col = 0; col < L.width_px; ++col) {
      const std::size_t at = static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col);
      bool even = rays.crossings(L.x_of_col(col), L.y_of_row(row), columns[at]);
      for (int k = 1; !even && k <= 4; ++k)
        even = rays.crossings(L.x_of_col(col) + k * 1.1e-7, L.y_of_row(row) + k * 0.7e-7, columns[at]);
      odd[at] = !even;
      odd_columns += !even;
    }
  std::int64_t checked = 0, inside = 0, skipped = 0, mismatches = 0;
  for (double z : {1.0, 4.0, 7.5, 10.5}) {
    const int layer = static_cast<int>((z - L.z0_mm) / L.layer_mm);
    const double zl = L.z_of_layer(layer);
    std::vector<int> owner;
    owner = slicer.slice_layer(layer, {.owner = true}).owner;
    auto in_teapot = [&](int col, int row) {
      if (col < 0 || row < 0 || col >= L.width_px || row >= L.height_px) return false;
      return test::VerticalRays::inside(columns[static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)],
                                        zl);
    };
    for (int row = 1; row + 1 < L.height_px; ++row)
      for (int col = 1; col + 1 < L.width_px; ++col) {
        const std::size_t at = static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col);
        const bool in = in_teapot(col, row);
        bool skip = odd[at] || odd[at - 1] || odd[at + 1] || odd[at - width] || odd[at + width] ||
                    in_teapot(col - 1, row) != in || in_teapot(col + 1, row) != in || in_teapot(col, row - 1) != in ||
                    in_teapot(col, row + 1) != in;
        for (double zc : columns[at]) skip = skip || std::abs(zc - zl) <= L.layer_mm;
        if (skip) {
          ++skipped;
          continue;
        }
        ++checked;
        inside += in;
        const bool owned = owner[at] == 0;  // the box holds the whole teapot
        if (owned != in) {
          ++mismatches;
          if (mismatches <= 20)
            ADD_FAILURE() << "layer " << layer << " pixel " << col << ", " << row << ": sliced "
                          << (owned ? "inside" : "outside") << ", vertical rays say " << (in ? "inside" : "outside");
        }
      }
  }
  std::cout << "teapot-trimmed box: " << checked << " pixels checked (" << inside << " inside), " << skipped
            << " near the surface or a seam not checked, " << mismatches << " disagree; " << odd_columns << " of "
            << columns.size() << " vertical lines crossed an odd number of times\n";
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(inside, 20000);
  EXPECT_GT(checked - inside, 20000);
  EXPECT_LT(odd_columns, static_cast<std::int64_t>(columns.size()) / 50);
}

}  // namespace
}  // namespace trivox
