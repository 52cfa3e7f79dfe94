// Cached volumes against their inputs (construction_probe.h).
#include "scene/construction_probe.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace trivox::detail {

namespace {

// Surface parameters as fractions of its domain: the corners, where every constructor's
// relation is exact (clamped ends), and one point inside.
constexpr std::array<std::array<double, 2>, 5> kFractions = {{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {0.37, 0.61}}};

double at_fraction(double lo, double hi, double f) { return f >= 1 ? hi : lo + f * (hi - lo); }

Vec3 surface_at(const TensorSpline& s, std::array<double, 2> f) {
  const double t[2] = {at_fraction(s.lo(0), s.hi(0), f[0]), at_fraction(s.lo(1), s.hi(1), f[1])};
  double out[3] = {0, 0, 0};
  s.evaluate(t, out);
  return {out[0], out[1], out[2]};
}

Vec3 curve_at(const TensorSpline& c, double f) {
  const double t[1] = {at_fraction(c.lo(0), c.hi(0), f)};
  double out[3] = {0, 0, 0};
  c.evaluate(t, out);
  return {out[0], out[1], out[2]};
}

// The volume at fractions `f` of its domain.
Vec3 volume_at(const Volume& v, Vec3 f) {
  const ParamBox& d = v.domain();
  return v.evaluate(
      {at_fraction(d.lo.x, d.hi.x, f.x), at_fraction(d.lo.y, d.hi.y, f.y), at_fraction(d.lo.z, d.hi.z, f.z)});
}

// The two directions beside `fixed`, in order.
std::array<int, 2> other_directions(int fixed) {
  return fixed == 0 ? std::array<int, 2>{1, 2} : fixed == 1 ? std::array<int, 2>{0, 2} : std::array<int, 2>{0, 1};
}

Vec3 face_fractions(int fixed, bool at_hi, std::array<int, 2> dirs, std::array<double, 2> f) {
  Vec3 p;
  p[fixed] = at_hi ? 1.0 : 0.0;
  p[dirs[0]] = f[0];
  p[dirs[1]] = f[1];
  return p;
}

// Rounding of the constructors' exact arithmetic (degree raising, knot insertion, blends) is
// some ulps of the coordinates; a replaced entry is off by millimetres. A millionth of the
// inputs' size separates the two.
double tolerance_of(const TensorSpline& s, double more_mm = 0) {
  const Box3 b = s.control_box();
  return 1e-6 * std::max({1.0, max_abs(b.lo), max_abs(b.hi)}) + more_mm;
}

std::string mismatch(std::string_view what, Vec3 f, double off_mm) {
  return fmt::format("at the parameters ({:.3g}, {:.3g}, {:.3g}) of its domain {} is {:.6g} mm off", f.x, f.y, f.z,
                     what, off_mm);
}

}  // namespace

std::optional<std::string> probe_faces(const Volume& volume, std::span<const FaceProbe> faces) {
  for (const FaceProbe& face : faces) {
    const double tol = tolerance_of(*face.surface) + 1e-6 * max_abs(face.offset_mm);
    for (const auto& f : kFractions) {
      const Vec3 at = face_fractions(face.fixed, face.at_hi, face.dirs, f);
      const double off = norm(volume_at(volume, at) - (surface_at(*face.surface, f) + face.offset_mm));
      if (!(off <= tol)) return mismatch("the face its inputs give", at, off);
    }
  }
  return std::nullopt;
}

std::optional<std::string> probe_coons(const Volume& volume, const std::array<TensorSpline, 6>& faces) {
  std::array<FaceProbe, 6> probes;
  for (std::size_t i = 0; i < 6; ++i) {
    // Face u0/u1 is parametrized by (v, w), v0/v1 by (u, w), w0/w1 by (u, v).
    const int fixed = static_cast<int>(i / 2);
    probes[i] = FaceProbe{&faces[i], fixed, i % 2 == 1, other_directions(fixed), {}};
  }
  return probe_faces(volume, probes);
}

std::optional<std::string> probe_revolve(const Volume& volume, const TensorSpline& profile, const RevolveParams& p) {
  const int fixed = p.angle_direction;
  const std::array<int, 2> dirs = other_directions(fixed);
  const FaceProbe start{&profile, fixed, false, dirs, {}};
  if (auto problem = probe_faces(volume, std::span(&start, 1))) return problem;
  const Vec3 k = (1.0 / norm(p.axis_dir)) * p.axis_dir;
  const double tol = tolerance_of(profile) + 1e-6 * max_abs(p.axis_point_mm);
  const double cos_angle = std::cos(p.angle_deg * 3.14159265358979323846 / 180.0);
  for (const auto& f : kFractions) {
    const Vec3 at = face_fractions(fixed, true, dirs, f);
    const Vec3 a = surface_at(profile, f) - p.axis_point_mm, b = volume_at(volume, at) - p.axis_point_mm;
    const Vec3 ra = a - dot(a, k) * k, rb = b - dot(b, k) * k;
    const double r = norm(ra);
    // Height along the axis, distance from it, and the angle turned (its cosine, so that the
    // sense of turning is not assumed), each against the tolerance in millimetres.
    const double off = std::max({std::abs(dot(a, k) - dot(b, k)), std::abs(r - norm(rb)),
                                 r > 0 ? std::abs(dot(ra, rb) / r - r * cos_angle) : 0.0});
    if (!(off <= tol)) return mismatch("the profile turned by the angle", at, off);
  }
  return std::nullopt;
}

std::optional<std::string> probe_sweep(const Constructed& built, const TensorSpline& section,
                                       const TensorSpline& path) {
  const double tol = std::max(tolerance_of(section), tolerance_of(path)) + built.report.approximation_error_mm;
  for (const bool end : {false, true}) {
    const Vec3 origin = curve_at(path, end ? 1.0 : 0.0);
    for (const auto& f : kFractions) {
      const Vec3 at = face_fractions(2, end, {0, 1}, f);
      const double off = std::abs(norm(volume_at(built.volume, at) - origin) - norm(surface_at(section, f)));
      if (!(off <= tol)) return mismatch("the section placed at the path's end", at, off);
    }
  }
  return std::nullopt;
}

std::optional<std::string> probe_shell(const Constructed& built, const TensorSpline& surface, const ShellParams& p) {
  const double t = p.thickness_mm;
  // Where the surface lies between the two faces (shell.h): at w = 0, 1 or halfway.
  const double share = p.side == ShellSide::kOutside ? 0.0 : p.side == ShellSide::kInside ? 1.0 : 0.5;
  const double tol = tolerance_of(surface) + 1e-6 * t + built.report.approximation_error_mm;
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& f = kFractions[i];
    const Vec3 lo = volume_at(built.volume, {f[0], f[1], 0}), hi = volume_at(built.volume, {f[0], f[1], 1});
    const double off = std::max(std::abs(norm(hi - lo) - t), norm(lo + share * (hi - lo) - surface_at(surface, f)));
    if (!(off <= tol)) return mismatch("the surface and its offset by the thickness", {f[0], f[1], 0}, off);
  }
  return std::nullopt;
}

}  // namespace trivox::detail
