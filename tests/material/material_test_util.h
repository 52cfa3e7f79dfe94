// Helpers for the material tests: rows of sample points and fraction buffers.
#pragma once

#include <random>
#include <vector>

#include "trivox/material/material_function.h"

namespace trivox::test {

// n random parameters in `box` (fixed seed: the tests are deterministic).
inline std::vector<Vec3> random_params(const ParamBox& box, std::size_t n, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Vec3> out(n);
  for (Vec3& p : out)
    for (int d = 0; d < 3; ++d) p[d] = box.lo[d] + U(rng) * (box.hi[d] - box.lo[d]);
  return out;
}

// Evaluates a row and returns its n*m fractions.
inline std::vector<float> eval_row(const MaterialFunction& f, const std::vector<Vec3>& uvw,
                                   const std::vector<Vec3>& xyz) {
  std::vector<float> out(uvw.size() * static_cast<std::size_t>(f.num_materials()), -7.0f);
  f.evaluate_row(uvw, xyz, out);
  return out;
}

// One sample's m fractions.
inline std::vector<float> eval_one(const MaterialFunction& f, Vec3 uvw, Vec3 xyz = {}) {
  std::vector<float> out(static_cast<std::size_t>(f.num_materials()), -7.0f);
  f.evaluate(uvw, xyz, out);
  return out;
}

}  // namespace trivox::test
