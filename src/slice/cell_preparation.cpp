#include "cell_preparation.h"

#include <functional>

namespace trivox::detail {

TrivariatePlan plan_trivariates(const Scene& scene) {
  TrivariatePlan plan;
  std::vector<int> of_volume(scene.volumes.size(), -1);
  auto volume_trivariate = [&](int v) {
    int& t = of_volume.at(static_cast<std::size_t>(v));
    if (t < 0) {
      t = static_cast<int>(plan.trivariates.size());
      const SceneVolume& sv = scene.volumes[static_cast<std::size_t>(v)];
      plan.trivariates.push_back({&sv.volume, sv.folds});
    }
    return t;
  };
  for (const Cell& c : scene.cells) {
    if (c.scene_volume >= 0) {
      plan.of_cell.push_back(volume_trivariate(c.scene_volume));
    } else {
      plan.of_cell.push_back(static_cast<int>(plan.trivariates.size()));
      plan.trivariates.push_back({&c.volume, c.folds});
    }
    std::vector<int>& clauses = plan.of_clause.emplace_back();
    for (const TrimClause& clause : c.trim.clauses)
      clauses.push_back(clause.kind == TrimKind::kVolume ? volume_trivariate(clause.volume) : -1);
  }
  return plan;
}

namespace {

// The cell's volume, clamped to its domain: a parametric trim's map into model space.
std::function<Vec3(Vec3)> through_volume(const Cell& c) {
  const Volume& volume = c.volume;
  return [&volume](Vec3 uvw) { return volume.evaluate(volume.domain().clamp(uvw)); };
}

}  // namespace

std::shared_ptr<const ShellMesh> TrimShellMeshes::mesh(const Cell& c, const TrimClause& clause, int max_samples) {
  const bool param = clause.kind == TrimKind::kParametric;
  auto& mesh = meshes_[{clause.shell.get(), param ? &c : nullptr}];
  if (!mesh) {
    mesh = param ? std::make_shared<ShellMesh>(*clause.shell, 1e-4 * norm(c.volume.domain().hi - c.volume.domain().lo),
                                               through_volume(c), outline_tolerance_mm_, max_samples)
                 : std::make_shared<ShellMesh>(*clause.shell, shell_tolerance_mm_, max_samples);
  }
  return mesh;
}

std::shared_ptr<const ShellMesh> TrimShellMeshes::outline(const Cell& c, const TrimClause& clause) {
  auto& outline = outlines_[{clause.shell.get(), &c}];
  if (!outline) outline = std::make_shared<ShellMesh>(meshes_.at({clause.shell.get(), &c})->mapped(through_volume(c)));
  return outline;
}

}  // namespace trivox::detail
