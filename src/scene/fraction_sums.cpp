#include "trivox/scene/fraction_sums.h"

#include <fmt/format.h>

#include "trivox/material/checked_material.h"

namespace trivox {

std::vector<CellFractionCheck> check_scene_fractions(const Scene& scene, const FractionCheckParams& params) {
  std::vector<std::string> names;
  for (const MaterialDef& m : scene.materials) names.push_back(m.name);
  std::vector<CellFractionCheck> out;
  for (std::size_t c = 0; c < scene.cells.size(); ++c) {
    const Cell& cell = scene.cells[c];
    // Scene cells carry their function inside the policy's wrapper: the check needs what it
    // wraps, and the policy.
    const auto* checked = dynamic_cast<const CheckedMaterial*>(cell.material.get());
    const MaterialFunction& inner = checked ? checked->inner() : *cell.material;
    const FractionPolicy& policy = checked ? checked->policy() : scene.fraction_policy;
    CellFractionCheck r{static_cast<int>(c), check_fractions(inner, policy, cell.volume.spline(), names, params)};
    const bool trimmed = !cell.trim.clauses.empty();
    if (trimmed && r.check.outcome == FractionCheckOutcome::kBroken) {
      r.check.outcome = FractionCheckOutcome::kUnproved;
      r.check.box = {r.check.uvw, r.check.uvw};
      r.check.reason = fmt::format("{} at (u,v,w) = ({:.6g}, {:.6g}, {:.6g}), which the cell's trim may cut away",
                                   r.check.rule, r.check.uvw.x, r.check.uvw.y, r.check.uvw.z);
    }
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<CellFractionCheck> check_scene_grey_sources(const Scene& scene, const FractionCheckParams& params) {
  const FractionPolicy finite_only{SumPolicy::kNormalise, 0.0};
  std::vector<CellFractionCheck> out;
  for (std::size_t c = 0; c < scene.cells.size(); ++c) {
    const Cell& cell = scene.cells[c];
    if (!cell.grey_source) continue;
    out.push_back({static_cast<int>(c), check_fractions(*cell.grey_source, finite_only, cell.volume.spline(),
                                                        {"greyscale source"}, params)});
  }
  return out;
}

}  // namespace trivox
