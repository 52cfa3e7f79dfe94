#include "newton.h"
#include "function_clones.h"

#include <cmath>

namespace trivox {

std::string_view to_string(InverseStatus s) noexcept {
  switch (s) {
    case InverseStatus::kConverged: return "converged";
    case InverseStatus::kOutside: return "outside";
    case InverseStatus::kNoConvergence: return "no-convergence";
    case InverseStatus::kSingular: return "singular";
  }
  return "unknown";
}

namespace detail {

namespace {
// det J counts as zero when it is negligible against the product of the column lengths (the
// volume of the parallelepiped against the volume its edges could span).
double singular_threshold(const Mat3& J) noexcept {
  const Vec3 a = J.column(0), b = J.column(1), c = J.column(2);
  return 1e-14 * std::sqrt(dot(a, a) * dot(b, b) * dot(c, c));  // one root on the hot path, not three
}
}  // namespace

TRIVOX_CLONED std::optional<double> certified_step_residual(const Volume& volume, Vec3 p, const Mat3& J, Vec3 r0,
                                                            Vec3 d) noexcept {
  const std::optional<Mat3>& M = volume.second_derivative_bounds();
  if (!M) return std::nullopt;
  // V(t + d) - x = (V(t) + J d - x) + R with |R| <= 0.5 sum_ij |d_i| |d_j| M(i, j) on the
  // segment from t to t + d (inside the box, which is convex). The first term is what the
  // linear solve left over; the last adds the rounding of V(t) and J, a few hundred ulps of
  // the coordinates' magnitude, far below any tolerance the slicer uses.
  const Vec3 a{std::abs(d.x), std::abs(d.y), std::abs(d.z)};
  const double taylor = 0.5 * dot(a, (*M) * a);
  const double linear = norm(J * d - r0);
  const double rounding = 1e-13 * (max_abs(p) + max_abs(J * a));
  const double bound = linear + taylor + rounding;
  if (!std::isfinite(bound)) return std::nullopt;
  return bound;
}

// Newton's step d solves J d = x - V. A step that would leave the box is cut back to the box
// (projected Newton); if the iterate then cannot move, x lies beyond that face. A step that
// increases the residual is halved (backtracking), which is checked lazily with the next
// evaluation so that the common, well-behaved case costs one evaluation per iteration.
TRIVOX_CLONED InverseResult newton_in_box(const Volume& volume, Vec3 x, Vec3 start, const ParamBox& box,
                                          const InverseParams& params) noexcept {
  InverseResult r;
  const Vec3 size = box.size();
  const double stall = 1e-13 * max_abs(size);
  Vec3 uvw = box.clamp(start);
  Vec3 prev_uvw = uvw, prev_step{};
  double prev_res = HUGE_VAL;
  int halvings = 0;
  for (int it = 1; it <= params.max_iterations; ++it) {
    Vec3 p;
    Mat3 J;
    volume.evaluate_jacobian(uvw, p, J);
    r.iterations = it;
    const Vec3 diff = x - p;
    const double res = norm(diff);
    r.uvw = uvw;
    r.residual = res;
    if (res <= params.residual_tolerance_model) {
      r.status = InverseStatus::kConverged;
      return r;
    }
    if (!(res < prev_res) && halvings < 8 && it > 1) {
      // The last step overshot: retreat halfway along it and try again.
      prev_step = 0.5 * prev_step;
      uvw = box.clamp(prev_uvw + prev_step);
      ++halvings;
      continue;
    }
    halvings = 0;
    Vec3 d;
    if (!solve3(J, diff, d, singular_threshold(J))) {
      r.status = InverseStatus::kSingular;
      return r;
    }
    const Vec3 target = uvw + d;
    const Vec3 next = box.clamp(target);
    bool pushed_out = false;
    for (int c = 0; c < 3; ++c)
      if (std::abs(target[c] - next[c]) > params.outside_slack_relative * size[c]) pushed_out = true;
    if (pushed_out && max_abs(next - uvw) <= stall) {
      r.status = InverseStatus::kOutside;
      return r;
    }
    // A full step whose end Taylor's remainder already places within the tolerance needs no
    // further evaluation (a clamped step is not the Newton step the bound is about).
    if (!pushed_out && next == target) {
      if (const std::optional<double> bound = certified_step_residual(volume, p, J, diff, d);
          bound && *bound <= params.residual_tolerance_model) {
        r.uvw = next;
        r.residual = *bound;
        r.status = InverseStatus::kConverged;
        return r;
      }
    }
    prev_uvw = uvw;
    prev_step = next - uvw;
    prev_res = res;
    uvw = next;
  }
  r.status = InverseStatus::kNoConvergence;
  return r;
}

TRIVOX_CLONED NewtonStepCheck check_newton_step(const Volume& volume, Vec3 x, Vec3 t, Vec3 p, const Mat3& J,
                                                const InverseParams& params) noexcept {
  NewtonStepCheck c;
  // Residuals are compared squared; the root is taken once, for the result.
  const double tol = params.residual_tolerance_model;
  const Vec3 r0 = x - p;
  if (dot(r0, r0) <= tol * tol) {
    c.converged = true;
    c.uvw = t;
    c.residual = norm(r0);
    return c;
  }
  Vec3 d;
  if (!solve3(J, r0, d, singular_threshold(J))) return c;
  const Vec3 target = t + d;
  if (!volume.domain().contains(target)) return c;
  if (const std::optional<double> bound = certified_step_residual(volume, p, J, r0, d); bound && *bound <= tol) {
    c.converged = true;
    c.uvw = target;
    c.residual = *bound;
    return c;
  }
  c.stepped = true;
  c.target = target;
  return c;
}

InverseResult invert_traced(const Volume& volume, Vec3 x, Vec3 seed_uvw, Vec3 seed_x, const Mat3& seed_jacobian,
                            const InverseParams& params, Mat3& jacobian) noexcept {
  const ParamBox& box = volume.domain();
  const Vec3 u0 = predict_from_seed(box, x, seed_uvw, seed_x, seed_jacobian);
  Vec3 p;
  volume.evaluate_jacobian(u0, p, jacobian);
  InverseResult r;
  r.iterations = 1;
  r.uvw = u0;
  const NewtonStepCheck c = check_newton_step(volume, x, u0, p, jacobian, params);
  if (c.converged) {
    r.uvw = c.uvw;
    r.residual = c.residual;
    r.status = InverseStatus::kConverged;
    return r;
  }
  if (c.stepped) {
    const Vec3 r1 = x - volume.evaluate(c.target);
    r.iterations = 2;
    r.uvw = c.target;
    const double tol = params.residual_tolerance_model;
    if (dot(r1, r1) <= tol * tol) {
      r.residual = norm(r1);
      r.status = InverseStatus::kConverged;
      return r;
    }
  }
  InverseResult full = newton_in_box(volume, x, r.uvw, box, params);
  full.iterations += r.iterations;
  if (full.status == InverseStatus::kConverged) {
    Vec3 unused;
    volume.evaluate_jacobian(full.uvw, unused, jacobian);
  }
  return full;
}

std::optional<Vec3> outward_hint(const Volume& volume, Vec3 x, Vec3 uvw) noexcept {
  const ParamBox& box = volume.domain();
  const Vec3 size = box.size();
  Vec3 p;
  Mat3 J;
  volume.evaluate_jacobian(uvw, p, J);
  const Vec3 away = x - p;
  int on_face = -1, faces = 0;
  for (int d = 0; d < 3; ++d)
    if (std::abs(uvw[d] - box.lo[d]) <= 1e-12 * size[d] || std::abs(uvw[d] - box.hi[d]) <= 1e-12 * size[d]) {
      on_face = d;
      ++faces;
    }
  Vec3 n = away;
  if (faces == 1) {
    n = cross(J.column((on_face + 1) % 3), J.column((on_face + 2) % 3));
    if (dot(n, away) < 0) n = -1.0 * n;
  }
  if (!(norm(n) > 0) || !std::isfinite(norm(n))) return std::nullopt;
  return n;
}

}  // namespace detail

InverseResult invert(const Volume& volume, Vec3 x, Vec3 hint, const InverseParams& params) {
  return detail::newton_in_box(volume, x, hint, volume.domain(), params);
}

InverseResult invert_from_neighbour(const Volume& volume, Vec3 x, const NeighbourSolution& n,
                                    const InverseParams& params, Mat3* jacobian) {
  Mat3 j;
  const InverseResult r = detail::invert_traced(volume, x, n.uvw, n.x, n.jacobian, params, j);
  if (jacobian) *jacobian = j;
  return r;
}

}  // namespace trivox
