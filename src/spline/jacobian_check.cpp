#include "trivox/spline/jacobian_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

std::string_view to_string(JacobianClass c) noexcept {
  switch (c) {
    case JacobianClass::kRightHanded: return "right-handed";
    case JacobianClass::kLeftHanded: return "left-handed";
    case JacobianClass::kDegenerate: return "degenerate";
    case JacobianClass::kFolded: return "folded";
  }
  return "unknown";
}

namespace {

// det J on the n x n x n grid of the domain (ends included), u fastest.
std::vector<double> sample_dets(const Volume& v, int n) {
  const ParamBox& dom = v.domain();
  std::vector<double> dets;
  dets.reserve(static_cast<std::size_t>(n * n * n));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 t{static_cast<double>(i) / (n - 1), static_cast<double>(j) / (n - 1),
                     static_cast<double>(k) / (n - 1)};
        const Vec3 uvw{dom.lo.x + t.x * (dom.hi.x - dom.lo.x), dom.lo.y + t.y * (dom.hi.y - dom.lo.y),
                       dom.lo.z + t.z * (dom.hi.z - dom.lo.z)};
        Vec3 p;
        Mat3 J;
        v.evaluate_jacobian(uvw, p, J);
        const double det = J.determinant();
        // An infinite or undefined det J is no shape of the volume but numbers beyond what a
        // double holds: said as such, not classified as a zero (a degenerate volume).
        if (!std::isfinite(det))
          throw ModelError(fmt::format(
              "the volume's numbers overflow: det J is {} at (u, v, w) = ({:.6g}, {:.6g}, {:.6g}) (control points "
              "too far out, or knot spans too short, for double precision)",
              det, uvw.x, uvw.y, uvw.z));
        dets.push_back(det);
      }
  return dets;
}

JacobianReport classify(const std::vector<double>& dets, const JacobianCheckParams& params) {
  JacobianReport r;
  double largest = 0.0;
  for (double d : dets) largest = std::max(largest, std::abs(d));
  r.min_det = *std::min_element(dets.begin(), dets.end());
  r.max_det = *std::max_element(dets.begin(), dets.end());
  const double zero = params.zero_relative * largest;
  for (double d : dets) {
    if (std::abs(d) <= zero)
      ++r.zero;
    else if (d > 0)
      ++r.positive;
    else
      ++r.negative;
  }
  if (r.positive > 0 && r.negative > 0)
    r.classification = JacobianClass::kFolded;
  else if (r.zero > 0)
    r.classification = JacobianClass::kDegenerate;
  else if (r.negative > 0)
    r.classification = JacobianClass::kLeftHanded;
  else
    r.classification = JacobianClass::kRightHanded;
  return r;
}

double grid_param(const ParamBox& dom, int axis, int i, int n) {
  return i == n - 1 ? dom.hi[axis] : dom.lo[axis] + static_cast<double>(i) / (n - 1) * (dom.hi[axis] - dom.lo[axis]);
}

}  // namespace

JacobianReport check_jacobian(const Volume& v, const JacobianCheckParams& params) {
  return classify(sample_dets(v, std::max(params.samples_per_direction, 2)), params);
}

std::vector<FoldRegion> fold_regions(const Volume& v, const JacobianCheckParams& params) {
  const int n = std::max(params.samples_per_direction, 2);
  const std::vector<double> dets = sample_dets(v, n);
  const JacobianReport r = classify(dets, params);
  if (r.classification != JacobianClass::kFolded) return {};
  double largest = 0.0;
  for (double d : dets) largest = std::max(largest, std::abs(d));
  const double zero = params.zero_relative * largest;
  const bool minority_negative = r.positive >= r.negative;
  auto index = [n](int i, int j, int k) { return static_cast<std::size_t>(i + n * (j + n * k)); };
  std::vector<char> minority(dets.size(), 0);
  for (std::size_t q = 0; q < dets.size(); ++q)
    minority[q] = std::abs(dets[q]) > zero && (dets[q] < 0) == minority_negative;

  // Connected sets by flood fill, each as a box of grid indices grown by one.
  struct IndexBox {
    std::array<int, 3> lo, hi;
    int samples;
  };
  std::vector<IndexBox> boxes;
  std::vector<char> seen(dets.size(), 0);
  std::vector<std::array<int, 3>> stack;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (!minority[index(i, j, k)] || seen[index(i, j, k)]) continue;
        IndexBox b{{i, j, k}, {i, j, k}, 0};
        seen[index(i, j, k)] = 1;
        stack.push_back({i, j, k});
        while (!stack.empty()) {
          const std::array<int, 3> c = stack.back();
          stack.pop_back();
          ++b.samples;
          for (int a = 0; a < 3; ++a) {
            b.lo[static_cast<std::size_t>(a)] =
                std::min(b.lo[static_cast<std::size_t>(a)], c[static_cast<std::size_t>(a)]);
            b.hi[static_cast<std::size_t>(a)] =
                std::max(b.hi[static_cast<std::size_t>(a)], c[static_cast<std::size_t>(a)]);
          }
          for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
              for (int di = -1; di <= 1; ++di) {
                const int x = c[0] + di, y = c[1] + dj, z = c[2] + dk;
                if (x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n) continue;
                const std::size_t q = index(x, y, z);
                if (!minority[q] || seen[q]) continue;
                seen[q] = 1;
                stack.push_back({x, y, z});
              }
        }
        for (std::size_t a = 0; a < 3; ++a) {
          b.lo[a] = std::max(b.lo[a] - 1, 0);
          b.hi[a] = std::min(b.hi[a] + 1, n - 1);
        }
        boxes.push_back(b);
      }
  // Grown boxes that overlap are one region.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t a = 0; a < boxes.size() && !merged; ++a)
      for (std::size_t b = a + 1; b < boxes.size() && !merged; ++b) {
        bool overlap = true;
        for (std::size_t c = 0; c < 3; ++c)
          overlap = overlap && boxes[a].lo[c] <= boxes[b].hi[c] && boxes[b].lo[c] <= boxes[a].hi[c];
        if (!overlap) continue;
        for (std::size_t c = 0; c < 3; ++c) {
          boxes[a].lo[c] = std::min(boxes[a].lo[c], boxes[b].lo[c]);
          boxes[a].hi[c] = std::max(boxes[a].hi[c], boxes[b].hi[c]);
        }
        boxes[a].samples += boxes[b].samples;
        boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(b));
        merged = true;
      }
  }
  std::sort(boxes.begin(), boxes.end(), [](const IndexBox& a, const IndexBox& b) {
    return std::tie(a.lo[0], a.lo[1], a.lo[2]) < std::tie(b.lo[0], b.lo[1], b.lo[2]);
  });
  std::vector<FoldRegion> out;
  const ParamBox& dom = v.domain();
  for (const IndexBox& b : boxes) {
    FoldRegion f;
    f.samples = b.samples;
    for (int a = 0; a < 3; ++a) {
      f.box.lo[a] = grid_param(dom, a, b.lo[static_cast<std::size_t>(a)], n);
      f.box.hi[a] = grid_param(dom, a, b.hi[static_cast<std::size_t>(a)], n);
    }
    out.push_back(f);
  }
  return out;
}

}  // namespace trivox
