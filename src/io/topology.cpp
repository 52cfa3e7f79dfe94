// Interfaces of a multi-patch model by sampling: each side of each patch is evaluated on a
// grid of 5 points per direction of the side (its corners, midpoints and quarter points, at
// parameters normalised to the patch's domain), and two sides are one face when some
// permutation and reversal of the side's directions carries one grid onto the other. This is
// G+Smo's own rule (gsMultiPatch::computeTopology compares the corners and the side centres)
// with more points, so that two faces which only share their corners are not glued.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "io/topology.h"
#include "trivox/error.h"

namespace trivox {

namespace {

constexpr int kGrid = 5;  // samples per direction of a side

struct SideSamples {
  PatchSide side;
  int point_dim = 0;
  std::array<int, 2> tangential{};  // the side's directions, increasing (param_dim - 1 of them)
  std::vector<double> values;       // kGrid^(param_dim-1) points, first tangential fastest
  const double* at(int k0, int k1) const {
    return values.data() + static_cast<std::size_t>((k0 + kGrid * k1) * point_dim);
  }
};

SideSamples sample_side(const TensorSpline& s, PatchSide side) {
  const int d = s.param_dim();
  SideSamples out;
  out.side = side;
  out.point_dim = s.point_dim();
  int t = 0;
  for (int dir = 0; dir < d; ++dir)
    if (dir != side.direction()) out.tangential[static_cast<std::size_t>(t++)] = dir;
  const int n0 = d >= 2 ? kGrid : 1, n1 = d >= 3 ? kGrid : 1;
  out.values.resize(static_cast<std::size_t>(n0 * n1 * s.point_dim()));
  std::array<double, 3> param{};
  for (int k1 = 0; k1 < n1; ++k1)
    for (int k0 = 0; k0 < n0; ++k0) {
      param[static_cast<std::size_t>(side.direction())] =
          side.at_end() ? s.hi(side.direction()) : s.lo(side.direction());
      const int k[2] = {k0, k1};
      for (int i = 0; i < d - 1; ++i) {
        const int dir = out.tangential[static_cast<std::size_t>(i)];
        const double f = static_cast<double>(k[i]) / (kGrid - 1);
        // The ends exactly, so that corners shared by construction compare equal.
        param[static_cast<std::size_t>(dir)] = k[i] == kGrid - 1 ? s.hi(dir) : s.lo(dir) + f * (s.hi(dir) - s.lo(dir));
      }
      s.evaluate(std::span<const double>(param.data(), static_cast<std::size_t>(d)),
                 std::span<double>(out.values)
                     .subspan(static_cast<std::size_t>((k0 + kGrid * k1) * s.point_dim()),
                              static_cast<std::size_t>(s.point_dim())));
    }
  return out;
}

bool close(const double* a, const double* b, int n, double tol) {
  double sum = 0;
  for (int c = 0; c < n; ++c) sum += (a[c] - b[c]) * (a[c] - b[c]);
  return std::sqrt(sum) <= tol;
}

// Whether side b is side a under the map that sends a's tangential direction i to b's
// tangential direction perm[i], reversed where flip[i].
bool matches(const SideSamples& a, const SideSamples& b, int d, const int perm[2], const bool flip[2], double tol) {
  const int n0 = d >= 2 ? kGrid : 1, n1 = d >= 3 ? kGrid : 1;
  for (int k1 = 0; k1 < n1; ++k1)
    for (int k0 = 0; k0 < n0; ++k0) {
      const int ka[2] = {k0, k1};
      int kb[2] = {0, 0};
      for (int i = 0; i < d - 1; ++i) kb[perm[i]] = flip[i] ? kGrid - 1 - ka[i] : ka[i];
      if (!close(a.at(k0, k1), b.at(kb[0], kb[1]), a.point_dim, tol)) return false;
    }
  return true;
}

}  // namespace

PatchTopology find_topology(const Model& model, double tolerance_relative) {
  PatchTopology topo;
  if (model.patches.empty()) return topo;
  const int d = model.patches.front().spline.param_dim();
  Box3 box;
  for (const Patch& p : model.patches) {
    if (p.spline.param_dim() != d)
      throw ModelError(
          fmt::format("patch '{}' has {} parameters and patch '{}' {}: a multi-patch topology joins "
                      "patches of one kind",
                      model.patches.front().name, d, p.name, p.spline.param_dim()));
    box.expand(p.spline.control_box());
  }
  const double tol = tolerance_relative * box.diagonal();

  std::vector<SideSamples> sides;
  for (std::size_t p = 0; p < model.patches.size(); ++p)
    for (int side = 1; side <= 2 * d; ++side)
      sides.push_back(sample_side(model.patches[p].spline, PatchSide{static_cast<int>(p), side}));
  // The centre sample is where every map sends the centre: a cheap test before the maps.
  const int centre = d == 1 ? 0 : (d == 2 ? kGrid / 2 : kGrid / 2 + kGrid * (kGrid / 2));
  auto centre_of = [&](const SideSamples& s) {
    return s.values.data() + static_cast<std::size_t>(centre * s.point_dim);
  };

  // The maps of a side's directions, identity first: for param_dim 3 both permutations with
  // every reversal, for 2 the two orientations, for 1 the one empty map.
  struct Map {
    int perm[2];
    bool flip[2];
  };
  std::vector<Map> maps;
  const int tangential = d - 1;
  const int perms = tangential == 2 ? 2 : 1;
  for (int pi = 0; pi < perms; ++pi)
    for (int f = 0; f < (1 << tangential); ++f) {
      Map m{{pi == 0 ? 0 : 1, pi == 0 ? 1 : 0}, {(f & 1) != 0, (f & 2) != 0}};
      maps.push_back(m);
    }

  std::vector<char> taken(sides.size(), 0);
  for (std::size_t i = 0; i < sides.size(); ++i) {
    if (taken[i]) continue;
    const SideSamples& a = sides[i];
    for (std::size_t j = i + 1; j < sides.size() && !taken[i]; ++j) {
      const SideSamples& b = sides[j];
      if (taken[j] || b.point_dim != a.point_dim) continue;
      if (!close(centre_of(a), centre_of(b), a.point_dim, tol)) continue;
      for (const Map& m : maps) {
        if (!matches(a, b, d, m.perm, m.flip, tol)) continue;
        PatchInterface f;
        f.first = a.side;
        f.second = b.side;
        const auto na = static_cast<std::size_t>(a.side.direction());
        f.dir_map[na] = b.side.direction();
        f.dir_orientation[na] = a.side.at_end() != b.side.at_end();
        for (int t = 0; t < tangential; ++t) {
          const auto ta = static_cast<std::size_t>(a.tangential[static_cast<std::size_t>(t)]);
          f.dir_map[ta] = b.tangential[static_cast<std::size_t>(m.perm[t])];
          f.dir_orientation[ta] = !m.flip[t];
        }
        topo.interfaces.push_back(f);
        taken[i] = taken[j] = 1;
        break;
      }
    }
  }
  for (std::size_t i = 0; i < sides.size(); ++i)
    if (!taken[i]) topo.boundary.push_back(sides[i].side);
  return topo;
}

}  // namespace trivox
