#include "trivox/slice/slicer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_preparation.h"
#include "check.h"
#include "coverage.h"
#include "slicer_parts.h"
#include "trivox/error.h"
#include "trivox/trim/detail/shell_mesh.h"

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

namespace {

// Vertices an outline mesh of a cell whose image spans `box` may take: about two per pixel
// of the box's six faces at printer resolution (a mesh finer than that decides no more
// pixels by itself), from 2^14 to 2^24.
std::int64_t pixel_budget(const Box3& box, const PrinterProfile& printer) {
  const Vec3 size = box.size();
  const double w = size.x / printer.pitch_x_mm() + 1, h = size.y / printer.pitch_y_mm() + 1,
               l = size.z / printer.layer_thickness_mm + 1;
  const double faces = 2 * (w * h + h * l + l * w);
  return static_cast<std::int64_t>(std::clamp(faces, double{1 << 14}, double{1 << 24}));
}

// Samples per direction of a shell's surfaces (the same for all) within `max_vertices`.
int shell_samples(const TrimShell& shell, std::int64_t max_vertices) {
  const auto surfaces = static_cast<double>(std::max<std::size_t>(1, shell.surfaces.size() + shell.trimmed.size()));
  return std::clamp(static_cast<int>(std::sqrt(static_cast<double>(max_vertices) / surfaces)), 3, 1024);
}

}  // namespace

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
  check_model_fits(finest_pitch_mm);
  prepare_cells();
  lay_out(finest_pitch_mm);
  build_meshes(finest_pitch_mm);
  // Greyscale: anti-aliased edges (coverage.h).
  if (scene.greyscale && scene.greyscale->antialiasing > 1)
    coverage_ = std::make_unique<detail::EdgeCoverage>(scene, params_, layout_);
}

Slicer::~Slicer() = default;

// The control points' box holds every cell, so its layout bounds the final one: checking it
// first refuses a job too large to lay out, or too far from the origin for a double to
// resolve its pixels, before anything is built.
void Slicer::check_model_fits(double finest_pitch_mm) const {
  const Box3 hull = scene_.bounds();
  if (hull.empty()) return;
  try {
    make_layout(hull, scene_.printer);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", scene_.source, e.what()));
  }
  const double far = std::max({std::abs(hull.lo.x), std::abs(hull.lo.y), std::abs(hull.lo.z), std::abs(hull.hi.x),
                               std::abs(hull.hi.y), std::abs(hull.hi.z)});
  // Pixel centres, outlines and inverses are computed in model coordinates: a thousandth of
  // a pixel must still be a difference a double can hold there.
  const double resolution = far * std::numeric_limits<double>::epsilon();
  if (!(resolution <= 1e-3 * finest_pitch_mm))
    throw Error(
        fmt::format("{}: the model reaches {:.6g} mm from the origin, where a double resolves only {:.3g} mm, "
                    "more than a thousandth of the printer's {:.4g} mm pitch; place it nearer the origin "
                    "(a placement's \"translate\")",
                    scene_.source, far, resolution, finest_pitch_mm));
}

namespace {

// Whether the material's bounds over the whole domain pin every fraction to one value (exact
// for the constant kind; sound for every kind, so a varying material never passes).
bool is_constant(const MaterialFunction& material, const ParamBox& domain) {
  const auto m = static_cast<std::size_t>(material.num_materials());
  std::vector<float> lo(m), hi(m);
  material.bounds(domain, lo, hi);
  return std::equal(lo.begin(), lo.end(), hi.begin());
}

}  // namespace

// The cells, their trivariates (each with its global solver) and their trim clauses; the
// meshes come later, once the layout gives their budgets.
void Slicer::prepare_cells() {
  const detail::TrivariatePlan plan = detail::plan_trivariates(scene_);
  for (const detail::TrivariatePlan::Trivariate& t : plan.trivariates) {
    trivariates_.push_back(std::make_unique<Trivariate>(*t.volume));
    if (t.folds) trivariates_.back()->fold.emplace(*t.volume);
  }
  int shell_slots = 0;
  for (std::size_t i = 0; i < scene_.cells.size(); ++i) {
    const Cell& c = scene_.cells[i];
    auto cd = std::make_unique<CellData>();
    cd->cell = &c;
    cd->trivariate = plan.of_cell[i];
    for (std::size_t j = 0; j < c.trim.clauses.size(); ++j) {
      const TrimClause& clause = c.trim.clauses[j];
      CellData::Clause k{clause.kind, clause.side, -1, nullptr, nullptr, -1, &clause};
      if (clause.kind == TrimKind::kVolume) {
        k.trivariate = plan.of_clause[i][j];
        trivariates_[static_cast<std::size_t>(k.trivariate)]->traced_first = true;
        cd->model_space_clauses = true;
      } else if (clause.kind == TrimKind::kParametric) {
        cd->parametric_clauses = true;
        cd->parametric_outlines = cd->parametric_outlines || clause.side == TrimSide::kInside;
      } else {
        k.shell_slot = shell_slots++;
        cd->model_space_clauses = true;
      }
      cd->clauses.push_back(std::move(k));
    }
    // The paper's strategies (Table 1) keep inverting every pixel, as the paper does.
    const bool own_strategy =
        params_.tracing == TracingStrategy::kPredict || params_.tracing == TracingStrategy::kFlood;
    cd->fills_interior = params_.fill_constant_interiors && own_strategy && cd->clauses.empty() && !c.grey_source &&
                         !trivariates_[static_cast<std::size_t>(cd->trivariate)]->fold &&
                         is_constant(*c.material, c.volume.domain());
    cells_.push_back(std::move(cd));
  }
}

// The frame and the layers come from the cells' volumes alone: the tight box of each image
// (GlobalSolver::image_bounds), never from an approximation of it, widened by a quarter of
// the finest pitch. A setting such as the outline tolerance cannot move them.
void Slicer::lay_out(double finest_pitch_mm) {
  for (const auto& tv : trivariates_) {
    if (params_.stop != nullptr && params_.stop->load()) throw CancelledError("stopped while bounding the cells");
    tv->image = tv->solver.image_bounds(1e-3 * finest_pitch_mm);
  }
  Box3 bounds;
  for (const auto& cd : cells_) bounds.expand(trivariates_[static_cast<std::size_t>(cd->trivariate)]->image);
  const double margin_mm = 0.25 * finest_pitch_mm;
  // A masked-resin printer builds from its platform: the first layer starts at the model's
  // bottom, as slicers for these printers lay it.
  const Vec3 grow{margin_mm, margin_mm, scene_.printer.display ? 0.0 : margin_mm};
  if (!bounds.empty()) bounds = Box3{bounds.lo - grow, bounds.hi + grow};
  layout_ = make_layout(bounds, scene_.printer);
}

// Outline meshes within their budgets (half the memory limit at most, shared out by the
// cells' sizes in pixels, before any is built), then the trim shells' meshes.
void Slicer::build_meshes(double finest_pitch_mm) {
  std::vector<std::int64_t> budgets;
  double wanted = 0;
  for (const auto& tv : trivariates_) {
    budgets.push_back(pixel_budget(tv->image.empty() ? Box3{} : tv->image, scene_.printer));
    wanted += static_cast<double>(budgets.back());
  }
  if (params_.memory_limit_bytes > 0) {
    const double allowed = 0.5 * static_cast<double>(params_.memory_limit_bytes) /
                           static_cast<double>(detail::kBoundaryMeshBytesPerVertex);
    if (wanted > allowed)
      for (std::int64_t& b : budgets)
        b = std::max<std::int64_t>(64, static_cast<std::int64_t>(static_cast<double>(b) * allowed / wanted));
  }
  for (std::size_t k = 0; k < trivariates_.size(); ++k) {
    Trivariate& tv = *trivariates_[k];
    detail::BoundaryMesh built =
        detail::build_boundary_mesh(*tv.volume, outline_tolerance_mm_, budgets[k], params_.stop);
    tv.mesh = std::move(built.mesh);
    // Pixels whose centres lie within twice the mesh's distance from the boundary are decided
    // by the exact inverse: the tolerance asked for, or what the budget allowed.
    tv.band_mm = 2.0 * std::max(outline_tolerance_mm_, built.deviation_mm);
  }

  // Model-space shells decide pixels by their tessellation alone: half the outline
  // tolerance when one is given, else an eighth of the finest pitch. Shells shared by
  // several clauses are tessellated once (cell_preparation.h); a parametric trim's
  // tessellation is also its outline once mapped through the cell's volume, refined until
  // that image lies within the outline tolerance too.
  const double shell_tolerance_mm =
      params_.outline_tolerance_mm ? 0.5 * *params_.outline_tolerance_mm : 0.125 * finest_pitch_mm;
  detail::TrimShellMeshes shells(shell_tolerance_mm, outline_tolerance_mm_);
  for (auto& cd : cells_) {
    const Cell& c = *cd->cell;
    const std::int64_t budget = budgets[static_cast<std::size_t>(cd->trivariate)];
    for (CellData::Clause& k : cd->clauses) {
      if (k.kind == TrimKind::kVolume) continue;
      if (params_.stop != nullptr && params_.stop->load()) throw CancelledError("stopped while meshing a trim shell");
      const TrimClause& clause = *k.source;
      k.mesh = shells.mesh(c, clause, shell_samples(*clause.shell, budget));
      if (k.mesh->open_edges() > 0)
        throw Error(fmt::format("{}: cell '{}': the shell {} is not closed ({} open edges)", scene_.source, c.name,
                                clause.shell->name, k.mesh->open_edges()));
      if (clause.kind == TrimKind::kParametric && clause.side == TrimSide::kInside)
        k.outline = shells.outline(c, clause);
    }
  }
}

std::uint64_t Slicer::tracing_bytes_per_worker() const noexcept {
  const auto pixels = static_cast<std::uint64_t>(layout_.width_px) * static_cast<std::uint64_t>(layout_.height_px);
  std::uint64_t bytes = detail::CellTracer::ring_bytes(layout_.width_px);
  // A constant-material cell's filled row (slice_cell).
  bytes += static_cast<std::uint64_t>(layout_.width_px) * detail::CellTracer::kTracedBytesPerPixel;
  for (const auto& tv : trivariates_)
    if (tv->traced_first) bytes += pixels * detail::CellTracer::kTracedBytesPerPixel;
  return bytes;
}

}  // namespace trivox
