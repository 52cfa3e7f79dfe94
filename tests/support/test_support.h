// Helpers shared by the tests: where the real data lives, analytic fixture volumes.
#pragma once

#include <filesystem>
#include <random>
#include <string>

#include "trivox/spline/volume.h"

namespace trivox::test {

// ../shared/data beside the repository, or an empty path when it is absent. Tests that
// need it call GTEST_SKIP() with shared_data_missing_message() in that case.
std::filesystem::path shared_data_dir();
std::string shared_data_missing_message();

// Analytic fixtures (exact where stated):
// a quarter of an annulus (inner radius r0, outer r1) extruded by height h along z, exact
// rational quadratic in v (the angle direction), linear in u (radius) and w (height).
Volume annulus_sector(double r0, double r1, double h);
// A 90-degree sector of a solid cylinder of radius r and height h (u = radius from 0:
// the face u = 0 collapses onto the axis).
Volume cylinder_sector(double r, double h);
// A cubic 8x8x8 B-spline volume on [0,1]^3 mapping a box of size (sx, sy, sz) with a twist
// about z, a bend along x over the height and rows bowed within each layer; regular
// (det J > 0) everywhere.
Volume twisted_bent_box(double sx, double sy, double sz, int ctrl = 8, int order = 4);
// The same kind of shape over any clamped knot vectors on [0, 1] (non-uniform ones too): a
// box of size `size` turned by `twist` radians about z over its height and bent along x by
// `bend` times its width (twisted_bent_box is twist 0.35, bend 0.15).
Volume twisted_bent_volume(const KnotVector& ku, const KnotVector& kv, const KnotVector& kw, Vec3 size, double twist,
                           double bend);

// A random rational trivariate with every kind of knot vector: unclamped in u (order 3),
// periodic in v (IRIT [KVP, order 4, 5 points), clamped with an interior knot in w (order 2);
// points in [-1, 1]^3, weights in [0.5, 2].
TensorSpline random_rational_spline(std::mt19937& rng);

}  // namespace trivox::test
