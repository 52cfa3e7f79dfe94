// LayerDecision: the preparation (once) and the per-layer steps that decide the points.
#include "layer_decision.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_preparation.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/material/material_function.h"

namespace trivox::detail {

namespace {

// Whether the material's bounds over the whole domain pin every fraction to one value (exact
// for the constant kind; sound for every kind, so a varying material never passes).
bool is_constant(const MaterialFunction& material, const ParamBox& domain) {
  const auto m = static_cast<std::size_t>(material.num_materials());
  std::vector<float> lo(m), hi(m);
  material.bounds(domain, lo, hi);
  return std::equal(lo.begin(), lo.end(), hi.begin());
}

// Samples per direction of a shell's surfaces (the same for all) within `max_vertices`.
int shell_samples(const TrimShell& shell, std::int64_t max_vertices) {
  const auto surfaces = static_cast<double>(std::max<std::size_t>(1, shell.surfaces.size() + shell.trimmed.size()));
  return std::clamp(static_cast<int>(std::sqrt(static_cast<double>(max_vertices) / surfaces)), 3, 1024);
}

}  // namespace

// The cells, their trivariates (each with its global solver) and their trim clauses; the
// meshes come later, once the caller's layout gives their budgets.
LayerDecision::LayerDecision(const Scene& scene, const SliceParams& params, Setup setup)
    : scene_(scene), params_(params), setup_(setup) {
  const TrivariatePlan plan = plan_trivariates(scene_);
  for (const TrivariatePlan::Trivariate& t : plan.trivariates) {
    trivariates_.push_back(std::make_unique<Trivariate>(*t.volume));
    if (t.folds) trivariates_.back()->fold.emplace(*t.volume);
  }
  int shell_slots = 0;
  for (std::size_t i = 0; i < scene_.cells.size(); ++i) {
    const trivox::Cell& c = scene_.cells[i];
    auto cd = std::make_unique<Cell>();
    cd->cell = &c;
    cd->trivariate = plan.of_cell[i];
    for (std::size_t j = 0; j < c.trim.clauses.size(); ++j) {
      const TrimClause& clause = c.trim.clauses[j];
      Clause k{clause.kind, clause.side, -1, nullptr, nullptr, -1, &clause};
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

void LayerDecision::bound_images(double tolerance_mm) {
  for (const auto& tv : trivariates_) {
    throw_if_stopped(params_.stop, "bounding the cells");
    tv->image = tv->solver.image_bounds(tolerance_mm);
  }
}

void LayerDecision::build_meshes(const std::vector<std::int64_t>& budgets) {
  const double tolerance_mm = setup_.outline_tolerance_mm;
  for (std::size_t k = 0; k < trivariates_.size(); ++k) {
    Trivariate& tv = *trivariates_[k];
    BoundaryMesh built = build_boundary_mesh(*tv.volume, tolerance_mm, budgets[k], params_.stop);
    tv.mesh = std::move(built.mesh);
    // Points whose centres lie within twice the mesh's distance from the boundary are decided
    // by the exact inverse: the tolerance asked for, or what the budget allowed.
    tv.band_mm = 2.0 * std::max(tolerance_mm, built.deviation_mm);
  }
  // Model-space shells decide points by their tessellation alone. Shells shared by several
  // clauses are tessellated once (cell_preparation.h); a parametric trim's tessellation is
  // also its outline once mapped through the cell's volume, refined until that image lies
  // within the outline tolerance too.
  TrimShellMeshes shells(setup_.shell_tolerance_mm, tolerance_mm);
  for (auto& cd : cells_) {
    const trivox::Cell& c = *cd->cell;
    const std::int64_t budget = budgets[static_cast<std::size_t>(cd->trivariate)];
    for (Clause& k : cd->clauses) {
      if (k.kind == TrimKind::kVolume) continue;
      throw_if_stopped(params_.stop, "meshing a trim shell");
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

void LayerDecision::decide(Layer& w, double z_mm, const RowSpans* only, const Consumer& consumer) const {
  w.z_mm = z_mm;
  trace_trimming_volumes(w, only);
  cut_trimming_shells(w);
  w.seconds_inverse += w.lap();
  // Cells in scene order: the consumer applies the owner rule (claim_point) as it goes.
  for (std::size_t ci = 0; ci < cells_.size(); ++ci) decide_cell(static_cast<int>(ci), w, only, consumer);
  w.seconds_inverse += w.lap();
}

// The trivariates that trim some cell are traced once for the whole layer, so every Boolean
// clause and every cell they parametrize read the same inside set (the cells "A only", "B
// only", "A and B" then partition the union by construction).
void LayerDecision::trace_trimming_volumes(Layer& w, const RowSpans* only) const {
  const SliceLayout& L = layout_;
  const auto width = static_cast<std::size_t>(L.width_px);
  const std::size_t points = width * static_cast<std::size_t>(L.height_px);
  w.traced_rows.resize(trivariates_.size());
  w.traced_inside.resize(trivariates_.size());
  for (std::size_t k = 0; k < trivariates_.size(); ++k) {
    const Trivariate& tv = *trivariates_[k];
    if (!tv.traced_first) continue;
    auto& rows = w.traced_rows[k];
    auto& in = w.traced_inside[k];
    rows.resize(static_cast<std::size_t>(L.height_px));
    in.assign(points, 0);
    if (!tv.candidates(L, w.z_mm, w.segments, w.spans)) continue;
    if (only) intersect_spans(w.spans, *only);
    CellTracer tracer(*tv.volume, tv.solver, params_, L.width_px, CellTracer::kDefaultRowsInFlight,
                      tv.fold.has_value());
    tracer.trace_layer(L, w.z_mm, w.spans, [&](int r, const TracedRow& row) {
      rows[static_cast<std::size_t>(r)] = row;
      for (int col : row.cols) in[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(col)] = 1;
    });
    w.counters += tracer.counters();
  }
}

// Each model-space shell is cut once and its crossings with every row's centre line kept.
void LayerDecision::cut_trimming_shells(Layer& w) const {
  for (const auto& cd : cells_)
    for (const auto& k : cd->clauses)
      if (k.shell_slot >= 0) {
        const auto slot = static_cast<std::size_t>(k.shell_slot);
        if (w.shell_rows.size() <= slot) w.shell_rows.resize(slot + 1);
        if (k.mesh->winding()) {
          // A mesh trim by the winding-number rule: the crossings signed (shell_mesh.h).
          if (w.shell_row_windings.size() <= slot) w.shell_row_windings.resize(slot + 1);
          k.mesh->mesh().cut(w.z_mm, w.segments, w.directions);
          shell_row_windings(w.segments, w.directions, layout_, w.shell_rows[slot], w.shell_row_windings[slot]);
          continue;
        }
        k.mesh->mesh().cut(w.z_mm, w.segments);
        shell_row_crossings(w.segments, layout_, w.shell_rows[slot]);
      }
}

bool LayerDecision::passes_shell_clause(const Clause& k, int col, int row, const Layer& w) const {
  const SliceLayout& L = layout_;
  const auto slot = static_cast<std::size_t>(k.shell_slot);
  const auto& xs = w.shell_rows[slot][static_cast<std::size_t>(row)];
  bool in;
  if (k.mesh->winding()) {
    const auto& windings = w.shell_row_windings[slot][static_cast<std::size_t>(row)];
    const double x = L.x_of_col(col);
    in = k.mesh->winding_inside(winding_beyond(xs, windings, x), {x, L.y_of_row(row), w.z_mm});
  } else {
    // A row through a seam's gap of a trimmed-surface shell is crossed an odd number of
    // times: its points are decided by the shell's vote (shell_mesh.h).
    in = k.mesh->gap_tolerant() && xs.size() % 2 == 1 ? k.mesh->contains({L.x_of_col(col), L.y_of_row(row), w.z_mm})
                                                      : inside_crossings(xs, L.x_of_col(col));
  }
  return in == (k.side == TrimSide::kInside);
}

bool LayerDecision::passes_model_space_clauses(const Cell& cd, int col, int row, const Layer& w) const {
  for (const auto& k : cd.clauses) {
    if (k.kind == TrimKind::kVolume) {
      const bool in = w.traced_inside[static_cast<std::size_t>(k.trivariate)]
                                     [static_cast<std::size_t>(row) * static_cast<std::size_t>(layout_.width_px) +
                                      static_cast<std::size_t>(col)] != 0;
      if (in != (k.side == TrimSide::kInside)) return false;
    } else if (k.kind == TrimKind::kShell) {
      if (!passes_shell_clause(k, col, row, w)) return false;
    }
  }
  return true;
}

bool LayerDecision::passes_parametric_clauses(const Cell& cd, Vec3 uvw) {
  for (const auto& k : cd.clauses)
    if (k.kind == TrimKind::kParametric && k.mesh->contains(uvw) != (k.side == TrimSide::kInside)) return false;
  return true;
}

void LayerDecision::throw_grey_not_finite(const trivox::Cell& cell, const TracedRow& row, std::size_t k,
                                          float value) const {
  const MaterialSite site{scene_.source, "/greyscale/source", cell.name, {}};
  throw FractionError(site, fmt::format("the greyscale source is {}, not a finite number", value), row.uvw[k],
                      &row.xyz[k]);
}

void LayerDecision::decide_cell(int ci, Layer& w, const RowSpans* only, const Consumer& consumer) const {
  const Cell& cd = *cells_[static_cast<std::size_t>(ci)];
  const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd.trivariate)];
  // The model-space clauses are tested on the traced points where they did not choose the
  // candidates.
  const bool test_model_space = tv.traced_first || (cd.model_space_clauses && !params_.model_space_narrowing);
  auto decide = [&](int r, const TracedRow& traced) { decide_row(ci, r, traced, test_model_space, w, consumer); };
  if (tv.traced_first) {
    // Traced already for the clauses it decides: its rows are read, not traced again.
    const auto& rows = w.traced_rows[static_cast<std::size_t>(cd.trivariate)];
    for (int r = 0; r < layout_.height_px; ++r) decide(r, rows[static_cast<std::size_t>(r)]);
    return;
  }
  if (!candidate_pixels(cd, w, only)) return;
  CellTracer tracer(*tv.volume, tv.solver, params_, layout_.width_px, CellTracer::kDefaultRowsInFlight,
                    tv.fold.has_value());
  tracer.trace_layer(layout_, w.z_mm, w.spans, decide);
  w.counters += tracer.counters();
  // The interior split off from the candidates (split_off_interior), filled.
  if (cd.fills_interior)
    for (int r = 0; r < layout_.height_px; ++r)
      if (!w.interior[static_cast<std::size_t>(r)].empty()) decide(r, interior_row(cd, r, w));
}

// Keeps the traced points the trims allow and evaluates the cell's material (and greyscale
// source) at them for the consumer.
void LayerDecision::decide_row(int ci, int r, const TracedRow& traced, bool test_model_space, Layer& w,
                               const Consumer& consumer) const {
  // Read before each row's material: a slow material (a Python callable) ends the layer within a
  // row of the stop flag, not at the layer's end.
  throw_if_stopped(params_.stop, "evaluating a layer's materials");
  const Cell& cd = *cells_[static_cast<std::size_t>(ci)];
  const TracedRow& row = cd.clauses.empty() ? traced : kept_by_trims(cd, r, traced, test_model_space, w);
  w.seconds_inverse += w.lap();
  const std::size_t n = row.cols.size();
  if (n != 0) {
    const auto m = static_cast<std::size_t>(scene_.num_materials());
    // Every value is written by the material (MaterialFunction::evaluate_row). Scene cells
    // carry their material already wrapped in the scene's fraction policy (CheckedMaterial).
    if (w.fractions.size() < n * m) w.fractions.resize(n * m);
    const std::span<float> fractions = std::span<float>(w.fractions).first(n * m);
    cd.cell->material->evaluate_row(row.uvw, row.xyz, fractions);
    std::span<float> grey;
    if (cd.cell->grey_source) {
      if (w.grey_scratch.size() < n) w.grey_scratch.resize(n);
      grey = std::span<float>(w.grey_scratch).first(n);
      cd.cell->grey_source->evaluate_row(row.uvw, row.xyz, grey);
      // A grey level from NaN would be the curve's first (a pixel exposed as if the source were
      // at its lowest): the first such point stops the job, as a fraction that breaks the rules does.
      for (std::size_t k = 0; k < n; ++k)
        if (!std::isfinite(grey[k])) throw_grey_not_finite(*cd.cell, row, k, grey[k]);
    }
    consumer(DecidedRow{ci, r, row, fractions, grey});
  }
  w.seconds_material += w.lap();
}

const TracedRow& LayerDecision::kept_by_trims(const Cell& cd, int r, const TracedRow& row, bool test_model_space,
                                              Layer& w) const {
  if (!test_model_space && !cd.parametric_clauses) return row;
  TracedRow& kept = w.kept;
  kept.cols.clear();
  kept.uvw.clear();
  kept.xyz.clear();
  for (std::size_t k = 0; k < row.cols.size(); ++k) {
    if (test_model_space && !passes_model_space_clauses(cd, row.cols[k], r, w)) continue;
    if (cd.parametric_clauses && !passes_parametric_clauses(cd, row.uvw[k])) continue;
    kept.cols.push_back(row.cols[k]);
    kept.uvw.push_back(row.uvw[k]);
    kept.xyz.push_back(row.xyz[k]);
  }
  return kept;
}

}  // namespace trivox::detail
