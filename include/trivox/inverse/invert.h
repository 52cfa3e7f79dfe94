// The inverse map x -> (u,v,w) of a trivariate (Equation 3 of the paper).
//
// Two solvers with explicit outcomes:
//  * invert(): damped Newton from a hint (typically a neighbouring pixel's solution), kept
//    inside the parameter box. Fast, local, allocation-free. On a polynomial volume the
//    last step is certified by Taylor's remainder (Volume::second_derivative_bounds) instead
//    of a final evaluation whenever that bound already meets the tolerance.
//  * GlobalSolver::solve(): finds every preimage of x in the whole domain or proves there is
//    none, by Bezier subdivision with bounding-box exclusion, an injectivity test that proves
//    a box holds at most one preimage, and Newton in the surviving boxes.
// Outside-the-volume is a result, not an error. Every tolerance below, its unit and its
// default are listed in docs/ARCHITECTURE.md, "Tolerances of the inverse map".
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "trivox/math.h"
#include "trivox/spline/volume.h"

namespace trivox {

struct InverseParams {
  // A parameter is a solution when |V(u,v,w) - x| (Euclidean) is at most this, in model units.
  double residual_tolerance_model = 1e-8;
  int max_iterations = 30;
  // How far outside the parameter box (as a fraction of the box size per direction) Newton
  // may want to step before the point is judged outside the domain.
  double outside_slack_relative = 1e-9;
};

enum class InverseStatus {
  kConverged,      // uvw is a solution inside the domain
  kOutside,        // the iteration is held at the domain boundary: x is (locally) outside
  kNoConvergence,  // iteration budget exhausted
  kSingular,       // the Jacobian vanished along the way
};
std::string_view to_string(InverseStatus s) noexcept;

struct InverseResult {
  InverseStatus status = InverseStatus::kNoConvergence;
  Vec3 uvw;  // last iterate (the solution when converged)
  // |V(uvw) - x| in model units, or an upper bound of it when the last Newton step was
  // certified rather than evaluated (polynomial volumes: see invert_from_neighbour).
  double residual = 0.0;
  int iterations = 0;  // evaluations of V (with or without J)
};

InverseResult invert(const Volume& volume, Vec3 x, Vec3 hint, const InverseParams& params = {});

// A solved point near x (for example the neighbouring pixel): its parameters, its position
// and V's Jacobian there.
struct NeighbourSolution {
  Vec3 uvw;
  Vec3 x;
  Mat3 jacobian;
};

// The tracing fast path: predicts u = n.uvw + J^-1 (x - n.x), takes one Newton step from the
// prediction and verifies the residual. For a polynomial volume the step is certified
// without evaluating V again when Taylor's remainder, bounded by the volume's
// second-derivative bounds, keeps |V(u) - x| within the tolerance (most points then cost one
// evaluation with Jacobian); otherwise a value-only evaluation checks it. Falls back to
// invert() from there when neither succeeds. A converged result always meets the residual
// tolerance (its `residual` is then the certified bound). When `jacobian` is given it
// receives V's Jacobian near the solution, ready to seed the next point.
InverseResult invert_from_neighbour(const Volume& volume, Vec3 x, const NeighbourSolution& n,
                                    const InverseParams& params = {}, Mat3* jacobian = nullptr);

struct GlobalSolveParams {
  InverseParams newton;
  // Boxes examined before giving up with kIncomplete (guards against degenerate volumes
  // where a whole face maps to one point).
  int max_boxes = 20000;
  // Preimages closer than this (fraction of the domain size, per direction) are one.
  double same_root_relative = 1e-6;
  // A preimage whose |det J| is below this fraction of the volume's typical |det J| is
  // singular (on a collapsed face or edge).
  double singular_relative = 1e-8;
  // Checked every 64 boxes: once it is true, solve() throws CancelledError (a solve of a
  // high-order rational volume may visit the whole box budget, seconds of work). May be set
  // from a signal handler or another thread. Not a setting of the result.
  const std::atomic<bool>* stop = nullptr;
};

enum class GlobalStatus {
  kNone,        // x has no preimage in the domain (proved by exclusion)
  kUnique,      // exactly one preimage
  kMultiple,    // more than one regular preimage: the volume folds over x
  kDegenerate,  // preimages only on a set where J is singular (e.g. a collapsed axis)
  kIncomplete,  // the box budget ran out; `preimages` holds what was found
};
std::string_view to_string(GlobalStatus s) noexcept;

struct Preimage {
  Vec3 uvw;
  double residual = 0.0;  // |V(uvw) - x|, model units
  double det = 0.0;       // det J at uvw
};

struct GlobalResult {
  GlobalStatus status = GlobalStatus::kNone;
  std::vector<Preimage> preimages;  // sorted by (u, v, w)
  int boxes_visited = 0;
};

class GlobalSolver {
 public:
  // Precomputes the Bezier pieces of `volume` (which must outlive the solver).
  explicit GlobalSolver(const Volume& volume);
  ~GlobalSolver();
  GlobalSolver(GlobalSolver&&) noexcept;
  GlobalSolver& operator=(GlobalSolver&&) noexcept;

  // `outward` (optional, any length): a direction along which x is believed to lie beyond
  // the image, such as the normal of the face where a failed Newton run stopped. Boxes
  // whose control points all lie below the plane through x with this normal are excluded
  // as well as those whose bounding box misses x; both exclusions are exact, so only the
  // work depends on the hint: points just outside a slanted face are then decided after a
  // few subdivisions instead of many.
  GlobalResult solve(Vec3 x, const GlobalSolveParams& params = {}, std::optional<Vec3> outward = {}) const;

  // The box of V's image over its whole domain, tight: each side lies beyond every point of
  // the image and within `tolerance_model` of some point of it (branch and bound over the
  // Bezier pieces, halved where their control points' extreme is not yet within the
  // tolerance of an extreme point found; both are exact bounds, by the convex hull property
  // and because a net's corners lie on the volume). Depends on the volume alone, never on an
  // approximation of it. Each side is widened by 64 units in the last place of the largest
  // coordinate, so that V's evaluations, which round, lie inside too. Once the nets halved
  // for one side hold `max_points` control points in all (the work, whatever the orders),
  // that side is the best upper bound found so far: still outside the image, not always
  // within the tolerance.
  Box3 image_bounds(double tolerance_model, std::int64_t max_points = 4'000'000) const;

 private:
  struct Pieces;
  const Volume* volume_;
  std::unique_ptr<const Pieces> pieces_;  // the Bezier pieces and their index (src/inverse)
  double typical_abs_det_ = 1.0;
};

// The certified inverse of one point: Newton from `hint` (invert), and where it does not
// converge, the global solver, which either finds the preimages or proves there is none. What
// a caller gets:
//   kConverged - Newton's solution, or where Newton failed the global solver's preimage
//                nearest the hint (its residual; a fold has several: the nearest is taken);
//   kOutside   - proved outside: the global solver excluded the whole domain (uvw is Newton's
//                last iterate, on the boundary);
//   kSingular  - preimages only where det J vanishes (a collapsed axis): the nearest one;
//   Newton's own status (kOutside, kNoConvergence, kSingular) where the solver's box budget
//                ran out before it found or excluded anything.
// `params.newton` runs both Newton's and the solver's iterations; `solver` must be built on
// `volume`. Python's Volume.invert does this by default, as `trivox probe` and the slicer
// decide what Newton alone cannot.
InverseResult invert_certified(const Volume& volume, const GlobalSolver& solver, Vec3 x, Vec3 hint,
                               const GlobalSolveParams& params = {});

}  // namespace trivox
