#include "trivox/slice/slicer.h"

#include <algorithm>
#include <functional>
#include <map>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "check.h"
#include "slicer_parts.h"
#include "trivox/error.h"
#include "trivox/trim/shell_mesh.h"

namespace trivox {

void Slicer::LayerBuffers::clear() {
  const auto m = static_cast<std::size_t>(grid.num_materials());
  for (std::size_t y = 0; y < written.size(); ++y) {
    auto& [first, last] = written[y];
    if (first > last) continue;
    TRIVOX_CHECK_GE(first, 0);
    TRIVOX_CHECK_LT(last, inside.width_px());
    const auto n = static_cast<std::size_t>(last - first + 1);
    std::fill_n(inside.row(static_cast<int>(y)).begin() + first, n, std::uint8_t{0});
    std::fill_n(grid.row(static_cast<int>(y)).begin() + static_cast<std::ptrdiff_t>(first * m), n * m, 0.0f);
    written[y] = {1, 0};
  }
}

std::unique_ptr<Slicer::LayerBuffers> Slicer::take_buffers() const {
  {
    const std::lock_guard lock(buffers_mutex_);
    if (!free_buffers_.empty()) {
      auto buffers = std::move(free_buffers_.back());
      free_buffers_.pop_back();
      return buffers;
    }
  }
  return std::make_unique<LayerBuffers>(layout_.width_px, layout_.height_px, scene_.num_materials());
}

void Slicer::give_back(std::unique_ptr<LayerBuffers> buffers) const {
  buffers->clear();
  const std::lock_guard lock(buffers_mutex_);
  free_buffers_.push_back(std::move(buffers));
}

std::unique_ptr<Slicer::Trivariate> Slicer::make_trivariate(const Volume& volume) const {
  return std::make_unique<Trivariate>(volume, detail::build_boundary_mesh(volume, outline_tolerance_mm_).mesh);
}

Slicer::Slicer(const Scene& scene, SliceParams params) : scene_(scene), params_(std::move(params)) {
  params_.validate();
  scene.printer.validate();
  dither_ = params_.dither.value_or(scene.dithering.value_or(DitherParams{}));
  dither_.validate();
  // An eighth of the finest pitch: the band of candidates the outline cannot decide, and so
  // the global solves that prove its pixels outside, halve with the tolerance, while the
  // outline meshes grow little (measured in docs/PERFORMANCE.md).
  const double finest_pitch_mm =
      std::min({scene.printer.pitch_x_mm(), scene.printer.pitch_y_mm(), scene.printer.layer_thickness_mm});
  outline_tolerance_mm_ = params_.outline_tolerance_mm.value_or(0.125 * finest_pitch_mm);
  // Model-space shells decide pixels by their tessellation alone: half the outline
  // tolerance when one is given, else an eighth of the finest pitch.
  const double shell_tolerance_mm =
      params_.outline_tolerance_mm ? 0.5 * *params_.outline_tolerance_mm : 0.125 * finest_pitch_mm;
  // The control points' box holds every cell, so its layout bounds the final one: checking it
  // first refuses a job too large to lay out before any outline is built.
  try {
    const Box3 hull = scene.bounds();
    if (!hull.empty()) make_layout(hull, scene.printer);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", scene.source, e.what()));
  }
  // Named volumes get a trivariate when some cell uses them; the others one per cell.
  std::vector<int> of_volume(scene.volumes.size(), -1);
  auto volume_trivariate = [&](int v) {
    auto& t = of_volume.at(static_cast<std::size_t>(v));
    if (t < 0) {
      t = static_cast<int>(trivariates_.size());
      const SceneVolume& sv = scene.volumes[static_cast<std::size_t>(v)];
      trivariates_.push_back(make_trivariate(sv.volume));
      if (sv.folds) trivariates_.back()->fold.emplace(sv.volume);
    }
    return t;
  };
  // Shells shared by several clauses are tessellated once: model-space shells to the shell
  // tolerance, parametric ones to 1e-4 of the cell's parameter box.
  std::map<std::pair<const TrimShell*, const Cell*>, std::shared_ptr<const ShellMesh>> shells, outlines;
  int shell_slots = 0;
  for (const Cell& c : scene.cells) {
    auto cd = std::make_unique<CellData>();
    cd->cell = &c;
    if (c.scene_volume >= 0) {
      cd->trivariate = volume_trivariate(c.scene_volume);
    } else {
      cd->trivariate = static_cast<int>(trivariates_.size());
      trivariates_.push_back(make_trivariate(c.volume));
      if (c.folds) trivariates_.back()->fold.emplace(c.volume);
    }
    for (const TrimClause& clause : c.trim.clauses) {
      CellData::Clause k{clause.kind, clause.side, -1, nullptr, nullptr, -1};
      if (clause.kind == TrimKind::kVolume) {
        k.trivariate = volume_trivariate(clause.volume);
        trivariates_[static_cast<std::size_t>(k.trivariate)]->traced_first = true;
        cd->model_space_clauses = true;
      } else {
        const bool param = clause.kind == TrimKind::kParametric;
        auto& mesh = shells[{clause.shell.get(), param ? &c : nullptr}];
        // A parametric trim's tessellation is also its outline once mapped through the cell's
        // volume (clamped to its domain, so a trim reaching past the domain's faces maps onto
        // them): it is refined until that image lies within the outline tolerance too.
        const Volume& volume = c.volume;
        const std::function<Vec3(Vec3)> through_volume = [&volume](Vec3 uvw) {
          return volume.evaluate(volume.domain().clamp(uvw));
        };
        if (!mesh) {
          const double tolerance =
              param ? 1e-4 * norm(c.volume.domain().hi - c.volume.domain().lo) : shell_tolerance_mm;
          auto m = param ? std::make_shared<ShellMesh>(*clause.shell, tolerance, through_volume, outline_tolerance_mm_)
                         : std::make_shared<ShellMesh>(*clause.shell, tolerance);
          if (m->open_edges() > 0)
            throw Error(fmt::format("{}: cell '{}': the shell {} is not closed ({} open edges)", scene.source, c.name,
                                    clause.shell->name, m->open_edges()));
          mesh = std::move(m);
        }
        k.mesh = mesh;
        if (param) {
          cd->parametric_clauses = true;
          if (clause.side == TrimSide::kInside) {
            auto& outline = outlines[{clause.shell.get(), &c}];
            if (!outline) outline = std::make_shared<ShellMesh>(mesh->mapped(through_volume));
            k.outline = outline;
            cd->parametric_outlines = true;
          }
        } else {
          k.shell_slot = shell_slots++;
          cd->model_space_clauses = true;
        }
      }
      cd->clauses.push_back(std::move(k));
    }
    cells_.push_back(std::move(cd));
  }
  Box3 bounds;
  for (const auto& cd : cells_) {
    const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd->trivariate)];
    bounds.expand(tv.fold ? tv.fold->bounds() : tv.mesh.bounds());  // a fold may reach past the outline
  }
  // The meshes lie within the tolerance of the true boundary; the layout keeps a margin of at
  // least a quarter of the finest pitch.
  const double margin_mm = std::max(outline_tolerance_mm_, 0.25 * finest_pitch_mm);
  const Vec3 grow{margin_mm, margin_mm, margin_mm};
  if (!bounds.empty()) bounds = Box3{bounds.lo - grow, bounds.hi + grow};
  layout_ = make_layout(bounds, scene.printer);
}

Slicer::~Slicer() = default;

}  // namespace trivox
