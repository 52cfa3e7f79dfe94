#include "trivox/material/detail/composite_material.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "material/enclosure_util.h"
#include "trivox/error.h"

namespace trivox {

namespace {

const MaterialFunction& require(const MaterialPtr& f, const char* what) {
  if (!f) throw Error(fmt::format("a composite material needs its {}", what));
  return *f;
}

int same_count(const MaterialPtr& a, const char* a_name, const MaterialPtr& b, const char* b_name) {
  const int m = require(a, a_name).num_materials();
  if (require(b, b_name).num_materials() != m)
    throw Error(fmt::format("the {} has {} materials but the {} has {}", a_name, m, b_name, b->num_materials()));
  return m;
}

void require_scalar(const MaterialPtr& s, const char* what) {
  if (require(s, what).num_materials() != 1)
    throw Error(fmt::format("the {} must be a scalar source (one value), not {} values", what, s->num_materials()));
}

// One row of a part: n samples of its outputs.
std::vector<float> evaluate_part(const MaterialFunction& f, std::span<const Vec3> uvw, std::span<const Vec3> xyz) {
  std::vector<float> out(uvw.size() * static_cast<std::size_t>(f.num_materials()));
  f.evaluate_row(uvw, xyz, out);
  return out;
}

float unit_clamp(float t) noexcept { return std::isnan(t) ? t : std::clamp(t, 0.0f, 1.0f); }

}  // namespace

BlendMaterial::BlendMaterial(MaterialPtr a, MaterialPtr b, MaterialPtr weight)
    : MaterialFunction(same_count(a, "first material", b, "second material")),
      a_(std::move(a)),
      b_(std::move(b)),
      weight_(std::move(weight)) {
  require_scalar(weight_, "weight");
}

void BlendMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                 std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const std::vector<float> a = evaluate_part(*a_, uvw, xyz), b = evaluate_part(*b_, uvw, xyz),
                           w = evaluate_part(*weight_, uvw, xyz);
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const float t = unit_clamp(w[s]);
    for (std::size_t j = 0; j < m; ++j) fractions[s * m + j] = (1.0f - t) * a[s * m + j] + t * b[s * m + j];
  }
}

ThresholdMaterial::ThresholdMaterial(MaterialPtr source, double level, MaterialPtr below, MaterialPtr above)
    : MaterialFunction(same_count(below, "material below", above, "material above")),
      source_(std::move(source)),
      level_(level),
      below_(std::move(below)),
      above_(std::move(above)) {
  require_scalar(source_, "source");
  if (!std::isfinite(level_)) throw Error(fmt::format("the threshold level {} is not a finite number", level_));
}

void ThresholdMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                     std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const std::vector<float> s = evaluate_part(*source_, uvw, xyz), lo = evaluate_part(*below_, uvw, xyz),
                           hi = evaluate_part(*above_, uvw, xyz);
  for (std::size_t i = 0; i < uvw.size(); ++i) {
    const std::vector<float>& pick = s[i] >= level_ ? hi : lo;  // NaN compares false: below
    std::copy_n(pick.begin() + static_cast<std::ptrdiff_t>(i * m), m,
                fractions.begin() + static_cast<std::ptrdiff_t>(i * m));
  }
}

SelectMaterial::SelectMaterial(std::vector<SelectRegion> regions, MaterialPtr otherwise, const ParamBox& cell_domain)
    : MaterialFunction(require(otherwise, "material outside every region").num_materials()),
      regions_(std::move(regions)),
      otherwise_(std::move(otherwise)),
      map_(AffineParamMap::between(cell_domain, kUnitParamBox)) {
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    const SelectRegion& region = regions_[r];
    const std::string what = fmt::format("material of region {}", r);
    if (require(region.material, what.c_str()).num_materials() != num_materials())
      throw Error(fmt::format("region {} has {} materials but the others have {}", r, region.material->num_materials(),
                              num_materials()));
    const double lo[3] = {region.box.lo.x, region.box.lo.y, region.box.lo.z};
    const double hi[3] = {region.box.hi.x, region.box.hi.y, region.box.hi.z};
    for (int d = 0; d < 3; ++d)
      if (!std::isfinite(lo[d]) || !std::isfinite(hi[d]) || lo[d] > hi[d])
        throw Error(
            fmt::format("region {}: the box [{}, {}] along direction {} is empty or not finite", r, lo[d], hi[d], d));
  }
}

void SelectMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                  std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  // Which region each sample falls in (regions_.size() = none), then each part is evaluated
  // once over the whole row and copied where it applies.
  std::vector<std::size_t> which(uvw.size(), regions_.size());
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const Vec3 p = map_(uvw[s]);
    for (std::size_t r = 0; r < regions_.size(); ++r) {
      const ParamBox& b = regions_[r].box;
      if (p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z && p.z <= b.hi.z) {
        which[s] = r;
        break;
      }
    }
  }
  for (std::size_t r = 0; r <= regions_.size(); ++r) {
    if (std::find(which.begin(), which.end(), r) == which.end()) continue;
    const MaterialFunction& f = r < regions_.size() ? *regions_[r].material : *otherwise_;
    const std::vector<float> part = evaluate_part(f, uvw, xyz);
    for (std::size_t s = 0; s < uvw.size(); ++s)
      if (which[s] == r)
        std::copy_n(part.begin() + static_cast<std::ptrdiff_t>(s * m), m,
                    fractions.begin() + static_cast<std::ptrdiff_t>(s * m));
  }
}

VoidMaskMaterial::VoidMaskMaterial(MaterialPtr material, MaterialPtr void_share)
    : MaterialFunction(require(material, "material").num_materials()),
      material_(std::move(material)),
      void_share_(std::move(void_share)) {
  require_scalar(void_share_, "void share");
}

void VoidMaskMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                    std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  material_->evaluate_row(uvw, xyz, fractions);
  const std::vector<float> v = evaluate_part(*void_share_, uvw, xyz);
  for (std::size_t s = 0; s < uvw.size(); ++s) {
    const float keep = 1.0f - unit_clamp(v[s]);
    for (std::size_t j = 0; j < m; ++j) fractions[s * m + j] *= keep;
  }
}

namespace {
int stops_count(const std::vector<GradientStop>& stops) {
  validate_gradient_stops(stops);
  return static_cast<int>(stops.front().fractions.size());
}
}  // namespace

TransferMaterial::TransferMaterial(MaterialPtr source, std::vector<GradientStop> stops)
    : MaterialFunction(stops_count(stops)), source_(std::move(source)), stops_(std::move(stops)) {
  require_scalar(source_, "source");
}

void TransferMaterial::evaluate_row(std::span<const Vec3> uvw, std::span<const Vec3> xyz,
                                    std::span<float> fractions) const {
  const auto m = static_cast<std::size_t>(num_materials());
  const std::vector<float> s = evaluate_part(*source_, uvw, xyz);
  for (std::size_t i = 0; i < uvw.size(); ++i) gradient_ramp(stops_, s[i], fractions.subspan(i * m, m));
}

namespace {

// The parts' enclosures as the float values the composition combines.
FractionEnclosure part(const MaterialFunction& f, const ParamBox& box, const Box3& xyz) {
  return detail::as_floats(f.enclose(box, xyz));
}

// {a + t (b - a) : a in A, b in B, t in T}, T within [0, 1]: bilinear, so the extremes are at
// the corners.
Interval lerp(const Interval& a, const Interval& b, const Interval& t) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double av : {a.lo, a.hi})
    for (double bv : {b.lo, b.hi})
      for (double tv : {t.lo, t.hi}) {
        const double v = (1.0 - tv) * av + tv * bv;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  return {lo, hi};
}

FractionEnclosure hull(const FractionEnclosure& a, const FractionEnclosure& b) {
  FractionEnclosure e = a;
  for (std::size_t j = 0; j < e.fractions.size(); ++j) e.fractions[j] = e.fractions[j].hull(b.fractions[j]);
  e.sum = e.sum.hull(b.sum);
  e.finite = a.finite && b.finite;
  return e;
}

}  // namespace

FractionEnclosure BlendMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  const FractionEnclosure a = part(*a_, box, xyz), b = part(*b_, box, xyz), w = part(*weight_, box, xyz);
  if (!w.finite) return FractionEnclosure::unknown(num_materials());  // a NaN weight gives NaN
  const Interval t = detail::unit_clamped(detail::scalar_of(w));
  FractionEnclosure e;
  e.fractions.resize(a.fractions.size());
  for (std::size_t j = 0; j < e.fractions.size(); ++j) e.fractions[j] = lerp(a.fractions[j], b.fractions[j], t);
  e.sum = lerp(a.sum, b.sum, t);
  e.finite = a.finite && b.finite;
  return detail::as_floats(e);
}

FractionEnclosure ThresholdMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  const FractionEnclosure s = part(*source_, box, xyz);
  const Interval v = detail::scalar_of(s);
  if (s.finite && v.hi < level_) return part(*below_, box, xyz);
  if (s.finite && v.lo >= level_) return part(*above_, box, xyz);
  return hull(part(*below_, box, xyz), part(*above_, box, xyz));  // NaN goes below: in the hull
}

FractionEnclosure SelectMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  const ParamBox b = map_(box);
  std::optional<FractionEnclosure> e;
  const auto include = [&](const MaterialFunction& f) {
    FractionEnclosure p = part(f, box, xyz);
    e = e ? hull(*e, p) : p;
  };
  for (const SelectRegion& r : regions_) {
    const ParamBox& rb = r.box;
    const bool meets = b.lo.x <= rb.hi.x && b.hi.x >= rb.lo.x && b.lo.y <= rb.hi.y && b.hi.y >= rb.lo.y &&
                       b.lo.z <= rb.hi.z && b.hi.z >= rb.lo.z;
    if (!meets) continue;
    include(*r.material);
    const bool holds = rb.lo.x <= b.lo.x && b.hi.x <= rb.hi.x && rb.lo.y <= b.lo.y && b.hi.y <= rb.hi.y &&
                       rb.lo.z <= b.lo.z && b.hi.z <= rb.hi.z;
    if (holds) return *e;  // every sample of the box is in this region or an earlier one
  }
  include(*otherwise_);
  return *e;
}

FractionEnclosure VoidMaskMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  FractionEnclosure e = part(*material_, box, xyz);
  const FractionEnclosure v = part(*void_share_, box, xyz);
  if (!v.finite) return FractionEnclosure::unknown(num_materials());
  const Interval t = detail::unit_clamped(detail::scalar_of(v));
  const Interval keep{1.0 - t.hi, 1.0 - t.lo};  // within [0, 1]
  const auto scale = [&](const Interval& f) {
    const double c[4] = {f.lo * keep.lo, f.lo * keep.hi, f.hi * keep.lo, f.hi * keep.hi};
    return Interval{std::min(std::min(c[0], c[1]), std::min(c[2], c[3])),
                    std::max(std::max(c[0], c[1]), std::max(c[2], c[3]))};
  };
  for (Interval& f : e.fractions) f = scale(f);
  e.sum = scale(e.sum);
  return detail::as_floats(e);
}

FractionEnclosure TransferMaterial::enclose(const ParamBox& box, const Box3& xyz) const {
  const FractionEnclosure s = part(*source_, box, xyz);
  return detail::ramp_enclosure(stops_, detail::scalar_of(s), s.finite);
}

}  // namespace trivox
