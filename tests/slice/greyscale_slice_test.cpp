// Greyscale layers (Scene::greyscale, src/slice/coverage.cpp):
//   - the calibration curve is applied exactly: every pixel's grey is the curve's level at the
//     pixel's scalar (a material's fraction, or a scalar source) as the slicer evaluates it;
//   - edges are anti-aliased from the exact geometry: the grey of every pixel agrees with its
//     exact covered fraction (computed analytically: a quarter annulus, two axis-aligned boxes
//     whose edges fall anywhere in their pixels, and a square turned by 30 degrees) times the
//     material's grey G: an edge pixel within half a sub-sample row of grey, G / (2k), plus one
//     level; a pixel holding a corner within G / k + 1 (two half rows); on average over a
//     curved or turned outline within G / k^2; for k = 2, 3, 4 and 8. Pixels away from every edge keep the grey of
//     their centre (no sub-sampling).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "trivox/inverse/invert.h"
#include "trivox/material/material_function.h"
#include "trivox/scene/fraction_sums.h"
#include "trivox/scene/scene.h"
#include "trivox/slice/slicer.h"

namespace trivox {
namespace {

const std::string kScenesDir = std::string(TRIVOX_EXAMPLES_DIR) + "/scenes";

Scene scene_from(const std::string& json) { return parse_scene(json, kScenesDir + "/greyscale-test.json"); }

std::string box_points(double x0, double y0, double z0, double x1, double y1, double z1) {
  return fmt::format(
      "[[{0},{1},{2}],[{3},{1},{2}],[{0},{4},{2}],[{3},{4},{2}],[{0},{1},{5}],[{3},{1},{5}],"
      "[{0},{4},{5}],[{3},{4},{5}]]",
      x0, y0, z0, x1, y1, z1);
}

// ---- exact areas ----

// The area of {x0 <= x <= x1, y0 <= y <= y1, x^2 + y^2 <= R^2} for 0 <= x0, 0 <= y0.
double disc_in_rect(double R, double x0, double x1, double y0, double y1) {
  if (x1 <= x0 || y1 <= y0 || x0 >= R || y0 >= R) return 0.0;
  auto G = [R](double x) {
    x = std::clamp(x, -R, R);
    return 0.5 * (x * std::sqrt(R * R - x * x) + R * R * std::asin(x / R));
  };
  const double h = y1 - y0;
  const double a = y1 < R ? std::sqrt(R * R - y1 * y1) : 0.0;  // for x <= a the disc covers the full height
  const double b = std::sqrt(R * R - y0 * y0);                 // for x >= b it covers nothing
  double area = h * std::max(0.0, std::min(x1, a) - x0);
  const double lo = std::max(x0, a), hi = std::min(x1, b);
  if (hi > lo) area += G(hi) - G(lo) - y0 * (hi - lo);
  return area;
}

// The area of a convex polygon clipped to a rectangle (Sutherland-Hodgman, shoelace).
double polygon_in_rect(std::vector<std::array<double, 2>> poly, double x0, double x1, double y0, double y1) {
  auto clip = [&](auto inside, auto cross) {
    std::vector<std::array<double, 2>> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const auto& p = poly[i];
      const auto& q = poly[(i + 1) % poly.size()];
      if (inside(p)) out.push_back(p);
      if (inside(p) != inside(q)) out.push_back(cross(p, q));
    }
    poly = std::move(out);
  };
  auto at_x = [](double x) {
    return [x](const std::array<double, 2>& p, const std::array<double, 2>& q) {
      const double t = (x - p[0]) / (q[0] - p[0]);
      return std::array<double, 2>{x, p[1] + t * (q[1] - p[1])};
    };
  };
  auto at_y = [](double y) {
    return [y](const std::array<double, 2>& p, const std::array<double, 2>& q) {
      const double t = (y - p[1]) / (q[1] - p[1]);
      return std::array<double, 2>{p[0] + t * (q[0] - p[0]), y};
    };
  };
  clip([&](const auto& p) { return p[0] >= x0; }, at_x(x0));
  clip([&](const auto& p) { return p[0] <= x1; }, at_x(x1));
  clip([&](const auto& p) { return p[1] >= y0; }, at_y(y0));
  clip([&](const auto& p) { return p[1] <= y1; }, at_y(y1));
  double twice = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const auto& p = poly[i];
    const auto& q = poly[(i + 1) % poly.size()];
    twice += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * std::abs(twice);
}

struct EdgeErrors {
  double largest = 0;         // over pixels crossed by an edge, without a corner
  double largest_corner = 0;  // over pixels holding a corner
  double mean = 0;            // over every partly covered pixel
  int edge_pixels = 0;
  int interior_mismatches = 0;
};

// Slices the middle layer and compares every pixel's grey with `grey` times its exact covered
// fraction; `corners` are the outline's corners.
EdgeErrors edge_errors(const Scene& scene, double grey,
                       const std::function<double(double, double, double, double)>& area,
                       const std::vector<std::array<double, 2>>& corners) {
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const LayerResult r = slicer.slice_layer(L.num_layers / 2);
  EXPECT_EQ(r.grey.width_px(), L.width_px);
  EXPECT_EQ(r.grey.height_px(), L.height_px);
  EdgeErrors e;
  double sum = 0.0;
  const double pixel_area = L.pitch_x_mm * L.pitch_y_mm;
  for (int row = 0; row < L.height_px; ++row)
    for (int col = 0; col < L.width_px; ++col) {
      const double x0 = L.x0_mm + col * L.pitch_x_mm, y1 = L.y_top_mm - row * L.pitch_y_mm;
      const double x1 = x0 + L.pitch_x_mm, y0 = y1 - L.pitch_y_mm;
      const double covered = area(x0, x1, y0, y1) / pixel_area;
      const double err = std::abs(r.grey.at(col, row) - grey * covered);
      if (std::getenv("TRIVOX_DEBUG_EDGES") && err > 20)
        fmt::print("col {} row {} grey {} covered {:.4f} err {:.1f}\n", col, row, r.grey.at(col, row), covered, err);
      const bool corner = std::any_of(corners.begin(), corners.end(), [&](const std::array<double, 2>& c) {
        return c[0] >= x0 - 1e-9 && c[0] <= x1 + 1e-9 && c[1] >= y0 - 1e-9 && c[1] <= y1 + 1e-9;
      });
      if (corner)
        e.largest_corner = std::max(e.largest_corner, err);
      else
        e.largest = std::max(e.largest, err);
      if (covered > 1e-9 && covered < 1 - 1e-9) {
        sum += err;
        ++e.edge_pixels;
      } else if (err > 0.5) {
        ++e.interior_mismatches;
      }
    }
  e.mean = e.edge_pixels > 0 ? sum / e.edge_pixels : 0.0;
  return e;
}

std::string greyscale_block(int k, double grey) {
  return fmt::format(
      R"("greyscale": {{ "source": {{ "material": "resin" }}, "curve": [[0, 0], [1, {}]], "antialiasing": {} }})", grey,
      k);
}

constexpr double kGrey = 200.0;  // the material's grey: not full exposure, so the curve scales it

// The mean bound holds where the edges cross their pixels at every offset (a curve, a turned
// edge); along an axis-aligned edge every pixel has the same offset, so the mean error is the
// error of that offset, anywhere up to the largest.
void expect_within_bounds(const EdgeErrors& e, int k, const std::string& what, bool offsets_vary = true) {
  EXPECT_GT(e.edge_pixels, 60) << what;
  EXPECT_LE(e.largest, kGrey / (2.0 * k) + 1.0) << what << ", k = " << k;
  EXPECT_LE(e.largest_corner, kGrey / k + 1.0) << what << ", k = " << k;
  if (offsets_vary) {
    EXPECT_LE(e.mean, kGrey / (k * k)) << what << ", k = " << k;
  }
  EXPECT_EQ(e.interior_mismatches, 0) << what << ", k = " << k;
  ::testing::Test::RecordProperty(
      fmt::format("{}_k{}", what, k),
      fmt::format("largest {:.2f}, at a corner {:.2f}, mean {:.2f}", e.largest, e.largest_corner, e.mean));
}

TEST(GreyscaleEdges, QuarterAnnulusAgreesWithTheExactCoveredArea) {
  for (int k : {2, 3, 4, 8}) {
    const Scene scene = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.2, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      {},
      "cells": [{{ "name": "annulus", "geometry": {{ "file": "../models/annulus_sector.itd" }}, "material": "resin" }}]
    }})",
                                               greyscale_block(k, kGrey)));
    // Radii 20 and 30 in the first quadrant.
    const EdgeErrors e = edge_errors(scene, kGrey,
                                     [](double x0, double x1, double y0, double y1) {
                                       x0 = std::max(x0, 0.0);
                                       y0 = std::max(y0, 0.0);
                                       if (x1 <= x0 || y1 <= y0) return 0.0;
                                       return disc_in_rect(30, x0, x1, y0, y1) - disc_in_rect(20, x0, x1, y0, y1);
                                     },
                                     {{20, 0}, {30, 0}, {0, 20}, {0, 30}});
    expect_within_bounds(e, k, "annulus");
  }
}

TEST(GreyscaleEdges, SquaresStraightAndTurnedAgreeWithTheExactCoveredArea) {
  for (int k : {2, 3, 4, 8}) {
    // A 4 x 3 mm box and a small one whose offset puts the first box's edges 0.37 and 0.81
    // of a pixel into their pixels (the layout starts at the small box's corner).
    const double p = 0.2, bx0 = -1.0 - 0.37 * p - 2 * p, by0 = -0.6 - 0.81 * p - 2 * p;
    const Scene straight = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.2, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      {},
      "cells": [{{ "name": "box", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }}, "material": "resin" }},
               {{ "name": "small", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }}, "material": "resin" }}]
    }})",
                                                  greyscale_block(k, kGrey), box_points(0, 0, 0, 4, 3, 1),
                                                  box_points(bx0, by0, 0, bx0 + 0.5, by0 + 0.4, 1)));
    auto rect = [](double x0, double x1, double y0, double y1, double a0, double a1, double b0, double b1) {
      return std::max(0.0, std::min(a1, x1) - std::max(a0, x0)) * std::max(0.0, std::min(b1, y1) - std::max(b0, y0));
    };
    expect_within_bounds(
        edge_errors(
            straight, kGrey,
            [&](double a0, double a1, double b0, double b1) {
              return rect(0, 4, 0, 3, a0, a1, b0, b1) + rect(bx0, bx0 + 0.5, by0, by0 + 0.4, a0, a1, b0, b1);
            },
            {{0, 0}, {4, 0}, {0, 3}, {4, 3}, {bx0, by0}, {bx0 + 0.5, by0}, {bx0, by0 + 0.4}, {bx0 + 0.5, by0 + 0.4}}),
        k, "boxes", false);

    // A 5 mm square turned by 30 degrees about (1, 2).
    const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
    std::vector<std::array<double, 2>> corners;
    for (const auto& [u, v] : std::vector<std::pair<double, double>>{{0, 0}, {5, 0}, {5, 5}, {0, 5}})
      corners.push_back({1 + c * u - s * v, 2 + s * u + c * v});
    std::string points = "[";
    for (double z : {0.0, 1.0})
      for (int j : {0, 1})
        for (int i : {0, 1}) {
          const auto& q = corners[static_cast<std::size_t>(j == 0 ? i : 3 - i)];
          points += fmt::format("{}[{},{},{}]", points.size() > 1 ? "," : "", q[0], q[1], z);
        }
    points += "]";
    const Scene turned = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.2, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      {},
      "cells": [{{ "name": "turned", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }}, "material": "resin" }}]
    }})",
                                                greyscale_block(k, kGrey), points));
    expect_within_bounds(
        edge_errors(
            turned, kGrey,
            [&](double a0, double a1, double b0, double b1) { return polygon_in_rect(corners, a0, a1, b0, b1); },
            corners),
        k, "turned");
  }
}

// Without anti-aliasing an edge pixel is all or nothing: the error reaches most of the grey,
// which the sub-samples bring within G / (2k) + 1.
TEST(GreyscaleEdges, WithoutSubSamplesEdgesAreAllOrNothing) {
  const Scene scene = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.2, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      {},
      "cells": [{{ "name": "annulus", "geometry": {{ "file": "../models/annulus_sector.itd" }}, "material": "resin" }}]
    }})",
                                             greyscale_block(1, kGrey)));
  const EdgeErrors e = edge_errors(scene, kGrey,
                                   [](double x0, double x1, double y0, double y1) {
                                     x0 = std::max(x0, 0.0);
                                     y0 = std::max(y0, 0.0);
                                     if (x1 <= x0 || y1 <= y0) return 0.0;
                                     return disc_in_rect(30, x0, x1, y0, y1) - disc_in_rect(20, x0, x1, y0, y1);
                                   },
                                   {});
  EXPECT_GT(e.largest, 0.7 * kGrey);
  EXPECT_GT(e.mean, kGrey / 8);
}

// The curve at every pixel's scalar, exactly: constant fractions per region of a box (so the
// fraction of a pixel is known exactly), and a scalar source (the expression x, in mm).
TEST(GreyscaleCalibration, EveryPixelIsTheCurvesLevelAtItsScalar) {
  const std::vector<std::pair<double, float>> regions = {
      {0.0, 0.0f}, {0.2, 0.3f}, {0.4, 0.5f}, {0.6, 0.75f}, {0.8, 1.0f}};
  std::string select;
  for (std::size_t i = 1; i < regions.size(); ++i)
    select += fmt::format(R"({}{{ "box": {{ "lo": [{}, 0, 0], "hi": [{}, 1, 1] }}, "material": {{ "kind": "constant",
      "fractions": {{ "stiff": {}, "soft": {} }} }} }})",
                          i > 1 ? "," : "", regions[i].first, i + 1 < regions.size() ? regions[i + 1].first : 1.0,
                          regions[i].second, 1.0f - regions[i].second);
  const GreyCalibration curve({{0.0, 30.0}, {0.3, 77.7}, {0.5, 130.0}, {1.0, 254.0}});
  const Scene scene = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.05, "layer_thickness_mm": 0.1, "max_materials": 2 }},
      "materials": [{{ "name": "stiff", "rgba": [255, 128, 64] }}, {{ "name": "soft", "rgba": [64, 128, 255] }}],
      "greyscale": {{ "source": {{ "material": "stiff" }}, "curve": [[0, 30], [0.3, 77.7], [0.5, 130], [1, 254]],
                      "antialiasing": 1 }},
      "cells": [{{ "name": "box", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }},
                 "material": {{ "kind": "select", "regions": [{}],
                               "otherwise": {{ "kind": "constant", "fractions": {{ "stiff": 0, "soft": 1 }} }} }} }}]
    }})",
                                             box_points(0, 0, 0, 5, 1, 0.5), select));
  const Slicer slicer(scene, {});
  const SliceLayout& L = slicer.layout();
  const LayerResult r = slicer.slice_layer(L.num_layers / 2);
  int checked = 0;
  std::vector<int> levels_seen(256, 0);
  for (int row = 0; row < L.height_px; ++row)
    for (int col = 0; col < L.width_px; ++col) {
      const double x = L.x_of_col(col), y = L.y_of_row(row);
      if (x < -1e-3 || x > 5 + 1e-3 || y < -1e-3 || y > 1 + 1e-3) {
        EXPECT_EQ(r.grey.at(col, row), 0) << col << ", " << row;
        continue;
      }
      const double u = x / 5;
      bool near_boundary = std::abs(x) < 1e-3 || std::abs(x - 5) < 1e-3 || std::abs(y) < 1e-3 || std::abs(y - 1) < 1e-3;
      float f = 0.0f;
      for (const auto& [lo, fraction] : regions) {
        near_boundary |= std::abs(u - lo) < 1e-4;
        if (u >= lo) f = fraction;
      }
      if (near_boundary) continue;
      EXPECT_EQ(r.grey.at(col, row), curve.level(static_cast<double>(f))) << "u = " << u;
      ++levels_seen[r.grey.at(col, row)];
      ++checked;
    }
  EXPECT_GT(checked, 1500);
  // The nodes give their greys exactly: 0 -> 30, 0.5 -> 130, 1 -> 254; 0.3f between nodes.
  for (int level : {30, 130, 254, static_cast<int>(curve.level(static_cast<double>(0.3f)))})
    EXPECT_GT(levels_seen[static_cast<std::size_t>(level)], 0) << level;
  EXPECT_EQ(curve.level(static_cast<double>(0.75f)), 192);  // 130 + 0.5 * 124

  // A scalar source: the position x (mm) through a curve over [0, 5].
  const Scene by_x = scene_from(fmt::format(R"({{
      "units": "mm", "printer": {{ "pixel_mm": 0.05, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      "greyscale": {{ "source": "x", "curve": [[0, 10], [2, 100], [5, 250]], "antialiasing": 1 }},
      "cells": [{{ "name": "box", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }}, "material": "resin" }}]
    }})",
                                            box_points(0, 0, 0, 5, 1, 0.5)));
  ASSERT_TRUE(by_x.greyscale);
  EXPECT_EQ(by_x.greyscale->material, -1);
  ASSERT_TRUE(by_x.cells[0].grey_source);
  const Slicer x_slicer(by_x, {});
  const SliceLayout& X = x_slicer.layout();
  const LayerResult rx = x_slicer.slice_layer(X.num_layers / 2);
  const GreyCalibration x_curve({{0, 10}, {2, 100}, {5, 250}});
  int inside = 0;
  for (int row = 0; row < X.height_px; ++row)
    for (int col = 0; col < X.width_px; ++col) {
      const double x = X.x_of_col(col), y = X.y_of_row(row);
      if (x < 1e-3 || x > 5 - 1e-3 || y < 1e-3 || y > 1 - 1e-3) continue;
      // The expression sees the pixel centre; its value is a float, as every scalar.
      EXPECT_EQ(rx.grey.at(col, row), x_curve.level(static_cast<double>(static_cast<float>(x)))) << x;
      ++inside;
    }
  EXPECT_GT(inside, 1500);
}

// A scalar source that is NaN (or infinite) somewhere stops the slicer at the first such pixel,
// naming the cell and the greyscale source, with and without anti-aliased edges; it never prints
// those pixels at the curve's first grey. trivox validate proves the source finite, or finds the
// point, beforehand (check_scene_grey_sources).
TEST(GreyscaleCalibration, ASourceThatIsNoNumberStopsTheSlicerNamingTheCell) {
  for (const char* source : {"sqrt(x - 2.5)", "1 / (x - x)"})
    for (int k : {1, 4}) {
      const Scene scene = scene_from(fmt::format(R"json({{
        "units": "mm", "printer": {{ "pixel_mm": 0.05, "layer_thickness_mm": 0.1, "max_materials": 1 }},
        "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
        "greyscale": {{ "source": "{}", "curve": [[0, 10], [5, 250]], "antialiasing": {} }},
        "cells": [{{ "name": "slab", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                   "points": {} }}, "material": "resin" }}]
      }})json",
                                                 source, k, box_points(0, 0, 0, 5, 1, 0.5)));
      const Slicer slicer(scene, {});
      try {
        (void)slicer.slice_layer(2);
        ADD_FAILURE() << source << ": a layer was sliced";
      } catch (const FractionError& e) {
        EXPECT_EQ(e.where(), "/greyscale/source") << e.what();
        EXPECT_EQ(e.cell(), "slab");
        EXPECT_NE(std::string(e.what()).find("not a finite number"), std::string::npos) << e.what();
      }
      const std::vector<CellFractionCheck> checks = check_scene_grey_sources(scene);
      ASSERT_EQ(checks.size(), 1u);
      EXPECT_NE(checks[0].check.outcome, FractionCheckOutcome::kProved) << source;
    }
  // A finite source is proved so.
  const Scene fine = scene_from(fmt::format(R"json({{
      "units": "mm", "printer": {{ "pixel_mm": 0.05, "layer_thickness_mm": 0.1, "max_materials": 1 }},
      "materials": [{{ "name": "resin", "rgba": [255, 128, 64] }}],
      "greyscale": {{ "source": "sqrt(x + 1)", "curve": [[0, 10], [5, 250]] }},
      "cells": [{{ "name": "slab", "geometry": {{ "orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
                 "points": {} }}, "material": "resin" }}]
    }})json",
                                            box_points(0, 0, 0, 5, 1, 0.5)));
  const std::vector<CellFractionCheck> checks = check_scene_grey_sources(fine);
  ASSERT_EQ(checks.size(), 1u);
  EXPECT_EQ(checks[0].check.outcome, FractionCheckOutcome::kProved);
}

}  // namespace
}  // namespace trivox
