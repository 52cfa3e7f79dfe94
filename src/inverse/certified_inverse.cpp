// invert_certified: Newton first, the global solver where Newton does not converge
// (trivox/inverse/invert.h).
#include <limits>

#include "trivox/inverse/invert.h"

namespace trivox {

namespace {

// The preimage nearest `hint` in parameter space; the first of equals (they are sorted).
const Preimage& nearest(const std::vector<Preimage>& preimages, Vec3 hint) {
  const Preimage* best = &preimages.front();
  double best_d2 = std::numeric_limits<double>::infinity();
  for (const Preimage& p : preimages) {
    const Vec3 d = p.uvw - hint;
    const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
    if (d2 < best_d2) best_d2 = d2, best = &p;
  }
  return *best;
}

}  // namespace

InverseResult invert_certified(const Volume& volume, const GlobalSolver& solver, Vec3 x, Vec3 hint,
                               const GlobalSolveParams& params) {
  InverseResult r = invert(volume, x, hint, params.newton);
  if (r.status == InverseStatus::kConverged) return r;
  const GlobalResult g = solver.solve(x, params);
  if (g.status == GlobalStatus::kNone) {
    r.status = InverseStatus::kOutside;
    return r;
  }
  if (g.preimages.empty()) return r;  // the budget ran out with nothing found: Newton's answer stands
  const Preimage& p = nearest(g.preimages, hint);
  r.uvw = p.uvw;
  r.residual = p.residual;
  r.status = g.status == GlobalStatus::kDegenerate ? InverseStatus::kSingular : InverseStatus::kConverged;
  return r;
}

}  // namespace trivox
