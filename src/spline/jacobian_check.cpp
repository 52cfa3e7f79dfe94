#include "trivox/spline/jacobian_check.h"

#include <algorithm>
#include <cmath>
#include <vector>

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

JacobianReport check_jacobian(const Volume& v, const JacobianCheckParams& params) {
  const int n = std::max(params.samples_per_direction, 2);
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
        dets.push_back(J.determinant());
      }
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

}  // namespace trivox
