// The Jacobian part of a construction report: the same sampling as check_jacobian, keeping
// where the minority sign and the zeros lie.
#include "trivox/construct/report.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace trivox {

namespace {

void add(JacobianRegion& r, Vec3 uvw) {
  if (r.samples == 0) {
    r.box = {uvw, uvw};
  } else {
    r.box.lo = {std::min(r.box.lo.x, uvw.x), std::min(r.box.lo.y, uvw.y), std::min(r.box.lo.z, uvw.z)};
    r.box.hi = {std::max(r.box.hi.x, uvw.x), std::max(r.box.hi.y, uvw.y), std::max(r.box.hi.z, uvw.z)};
  }
  ++r.samples;
}

std::string box_text(const ParamBox& b) {
  return fmt::format("u [{:.4g}, {:.4g}] v [{:.4g}, {:.4g}] w [{:.4g}, {:.4g}]", b.lo.x, b.hi.x, b.lo.y, b.hi.y, b.lo.z,
                     b.hi.z);
}

}  // namespace

ConstructionReport inspect_volume(const Volume& volume, const JacobianCheckParams& params) {
  ConstructionReport r;
  r.jacobian = check_jacobian(volume, params);
  // The same grid as check_jacobian, so the counts agree.
  const int n = std::max(params.samples_per_direction, 2);
  const ParamBox& d = volume.domain();
  const double zero = params.zero_relative * std::max(std::abs(r.jacobian.min_det), std::abs(r.jacobian.max_det));
  const bool minority_negative = r.jacobian.positive >= r.jacobian.negative;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const auto at = [n](double lo, double hi, int s) { return lo + (hi - lo) * static_cast<double>(s) / (n - 1); };
        const Vec3 uvw{at(d.lo.x, d.hi.x, i), at(d.lo.y, d.hi.y, j), at(d.lo.z, d.hi.z, k)};
        Vec3 p;
        Mat3 J;
        volume.evaluate_jacobian(uvw, p, J);
        const double det = J.determinant();
        if (std::abs(det) <= zero)
          add(r.zero, uvw);
        else if ((det < 0) == minority_negative)
          add(r.minority_sign, uvw);
      }
  return r;
}

std::string ConstructionReport::describe() const {
  const int total = jacobian.positive + jacobian.negative + jacobian.zero;
  std::string s = std::string(to_string(jacobian.classification));
  if (minority_sign.samples > 0)
    s += fmt::format(": det J {} 0 at {} of {} samples, in {}", jacobian.positive >= jacobian.negative ? "<" : ">",
                     minority_sign.samples, total, box_text(minority_sign.box));
  if (zero.samples > 0)
    s += fmt::format("{} det J = 0 at {} of {} samples, in {}", minority_sign.samples > 0 ? ";" : ":", zero.samples,
                     total, box_text(zero.box));
  return s;
}

}  // namespace trivox
