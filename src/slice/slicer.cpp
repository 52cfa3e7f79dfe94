#include "trivox/slice/slicer.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_tracer.h"
#include "fold_candidates.h"
#include "scanline.h"
#include "trivox/error.h"
#include "trivox/raster/dither.h"
#include "trivox/trim/shell_mesh.h"

namespace trivox {

// One trivariate, inverted once per pixel and layer however many cells use it.
struct Slicer::Trivariate {
  const Volume* volume;
  detail::BoundaryMesh mesh;
  GlobalSolver solver;
  // Traced for the whole layer before the cells (it trims some cell), rather than streamed
  // row by row for the one cell it parametrizes.
  bool traced_first = false;
  // A folded volume the scene accepts: candidates from its pieces' boxes, every pixel by the
  // global solver (fold_candidates.h, CellTracer).
  std::optional<detail::FoldCandidates> fold;

  Trivariate(const Volume& v, double tolerance_mm, bool folds)
      : volume(&v),
        mesh(v, tolerance_mm),
        solver(v),
        fold(folds ? std::optional(detail::FoldCandidates(v)) : std::nullopt) {}
  // The layer's candidate pixels; false when there are none.
  bool candidates(const SliceLayout& L, double z_mm, double margin_mm, std::vector<detail::Segment2>& segments,
                  detail::RowSpans& spans) const {
    if (fold) {
      fold->spans(L, z_mm, margin_mm, spans);
      return std::any_of(spans.begin(), spans.end(), [](const auto& row) { return !row.empty(); });
    }
    mesh.cut(z_mm, segments);
    if (segments.empty()) return false;
    detail::candidate_spans(segments, L, margin_mm, spans);
    return true;
  }
};

struct Slicer::CellData {
  struct Clause {
    TrimKind kind;
    TrimSide side;
    int trivariate = -1;                    // kVolume
    std::shared_ptr<const ShellMesh> mesh;  // kShell (model space), kParametric (u, v, w)
    // kParametric inside: `mesh` mapped through the cell's volume, the clause's outline in
    // model space (the pixels it keeps lie inside it, or within the outline margin).
    std::shared_ptr<const ShellMesh> outline;
    int shell_slot = -1;  // kShell: index of its cut in the layer's cuts
  };
  const Cell* cell;
  int trivariate;
  std::vector<Clause> clauses;
  bool model_space_clauses = false;  // any kVolume or kShell clause
  bool parametric_clauses = false;
  bool parametric_outlines = false;  // any kParametric clause with an outline
};

// A layer's dense rasters, handed out all zero and handed back all zero: the slicer clears
// only the span of each row that a layer wrote (every written grid pixel is an inside pixel).
struct Slicer::LayerBuffers {
  MaterialGrid grid;
  InsideMask inside;
  std::vector<std::pair<int, int>> written;  // per row: first and last column written, or {1, 0}

  LayerBuffers(int width_px, int height_px, int num_materials)
      : grid(width_px, height_px, num_materials),
        inside(width_px, height_px, 0),
        written(static_cast<std::size_t>(height_px), {1, 0}) {}

  void clear() {
    const auto m = static_cast<std::size_t>(grid.num_materials());
    for (std::size_t y = 0; y < written.size(); ++y) {
      auto& [first, last] = written[y];
      if (first > last) continue;
      const auto n = static_cast<std::size_t>(last - first + 1);
      std::fill_n(inside.row(static_cast<int>(y)).begin() + first, n, std::uint8_t{0});
      std::fill_n(grid.row(static_cast<int>(y)).begin() + static_cast<std::ptrdiff_t>(first * m), n * m, 0.0f);
      written[y] = {1, 0};
    }
  }
};

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

// The layer's state of the trivariates traced first and of the cut shells.
struct LayerTrims {
  std::vector<std::vector<detail::TracedRow>> rows;          // per trivariate (empty unless traced first)
  std::vector<std::vector<std::uint8_t>> inside;             // per trivariate, width x height
  std::vector<std::vector<std::vector<double>>> shell_rows;  // per cut shell: crossings per row
};

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
      trivariates_.push_back(std::make_unique<Trivariate>(sv.volume, outline_tolerance_mm_, sv.folds));
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
      trivariates_.push_back(std::make_unique<Trivariate>(c.volume, outline_tolerance_mm_, c.folds));
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
    bounds.expand(tv.fold ? tv.fold->bounds() : tv.mesh.bounds());
  }
  // The meshes lie within the tolerance of the true boundary; the layout keeps a margin of at
  // least a quarter of the finest pitch.
  const double margin_mm = std::max(outline_tolerance_mm_, 0.25 * finest_pitch_mm);
  const Vec3 grow{margin_mm, margin_mm, margin_mm};
  if (!bounds.empty()) bounds = Box3{bounds.lo - grow, bounds.hi + grow};
  layout_ = make_layout(bounds, scene.printer);
}

Slicer::~Slicer() = default;

LayerResult Slicer::slice_layer(int layer) const { return slice_layer(layer, nullptr); }

LayerResult Slicer::slice_layer(int layer, std::vector<int>* owner_out) const {
  const auto start = std::chrono::steady_clock::now();
  const SliceLayout& L = layout_;
  const int m = scene_.num_materials();
  const auto width = static_cast<std::size_t>(L.width_px);
  LayerResult result;
  LayerStats& st = result.stats;
  st.layer = layer;
  st.z_mm = L.z_of_layer(layer);
  st.pixels_total = static_cast<std::int64_t>(L.width_px) * L.height_px;

  // Not handed back when the layer throws: a buffer in the pool is always all zero.
  std::unique_ptr<LayerBuffers> buffers = take_buffers();
  MaterialGrid& grid = buffers->grid;
  InsideMask& inside = buffers->inside;
  // With one cell, a pixel's owner is that cell wherever the pixel is inside: no per-pixel
  // bookkeeping (at Voxel Print resolution it would be 5 bytes a pixel, 37 MB a layer).
  const bool several_cells = cells_.size() > 1;
  const float fraction_lo = -dither_.fraction_tolerance, fraction_hi = 1.0f + dither_.fraction_tolerance;
  const auto owned_pixels = several_cells ? static_cast<std::size_t>(st.pixels_total) : 0;
  std::vector<int> owner(owned_pixels, -1);
  std::vector<std::uint8_t> owner_gave_material(owned_pixels, 0);
  std::vector<detail::Segment2> segments;
  detail::RowSpans spans;
  detail::TracedRow kept;
  std::vector<float> fractions;
  detail::TraceCounters counters;

  using Clock = std::chrono::steady_clock;
  auto lap = [](Clock::time_point& t) {
    const auto now = Clock::now();
    const double d = std::chrono::duration<double>(now - t).count();
    t = now;
    return d;
  };
  auto t = Clock::now();

  // Trimmed cells: the trivariates that trim some cell are traced once for the whole layer,
  // so every Boolean clause and every cell they parametrize read the same inside set (the
  // cells "A only", "B only", "A and B" then partition the union by construction), and the
  // shells are cut once.
  LayerTrims trims;
  trims.rows.resize(trivariates_.size());
  trims.inside.resize(trivariates_.size());
  for (std::size_t k = 0; k < trivariates_.size(); ++k) {
    const Trivariate& tv = *trivariates_[k];
    if (!tv.traced_first) continue;
    auto& rows = trims.rows[k];
    auto& in = trims.inside[k];
    rows.resize(static_cast<std::size_t>(L.height_px));
    in.assign(static_cast<std::size_t>(st.pixels_total), 0);
    if (!tv.candidates(L, st.z_mm, 2.0 * outline_tolerance_mm_, segments, spans)) continue;
    detail::CellTracer tracer(*tv.volume, tv.solver, params_, L.width_px, detail::CellTracer::kDefaultRowsInFlight,
                              tv.fold.has_value());
    tracer.trace_layer(L, st.z_mm, spans, [&](int r, const detail::TracedRow& row) {
      rows[static_cast<std::size_t>(r)] = row;
      for (int col : row.cols) in[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(col)] = 1;
    });
    counters += tracer.counters();
  }
  std::vector<ShellSegment> shell_segments;
  std::vector<detail::Segment2> outline_segments;
  detail::RowSpans outline_spans;
  std::vector<std::array<Vec3, 3>> slab_triangles;
  for (const auto& cd : cells_)
    for (const auto& k : cd->clauses)
      if (k.shell_slot >= 0) {
        k.mesh->cut(st.z_mm, shell_segments);
        if (trims.shell_rows.size() <= static_cast<std::size_t>(k.shell_slot))
          trims.shell_rows.resize(static_cast<std::size_t>(k.shell_slot) + 1);
        detail::shell_row_crossings(shell_segments, L, trims.shell_rows[static_cast<std::size_t>(k.shell_slot)]);
      }
  // Whether pixel (col, row) satisfies a cell's model-space clauses (volumes and shells).
  auto model_space_ok = [&](const CellData& cd, int col, int row) {
    for (const auto& k : cd.clauses) {
      bool in;
      if (k.kind == TrimKind::kVolume)
        in = trims.inside[static_cast<std::size_t>(k.trivariate)]
                         [static_cast<std::size_t>(row) * width + static_cast<std::size_t>(col)] != 0;
      else if (k.kind == TrimKind::kShell) {
        const auto& xs = trims.shell_rows[static_cast<std::size_t>(k.shell_slot)][static_cast<std::size_t>(row)];
        // A row through a seam's gap of a trimmed-surface shell is crossed an odd number of
        // times: its pixels are decided by the shell's vote (shell_mesh.h).
        in = k.mesh->gap_tolerant() && xs.size() % 2 == 1
                 ? k.mesh->contains({L.x_of_col(col), L.y_of_row(row), st.z_mm})
                 : detail::inside_crossings(xs, L.x_of_col(col));
      } else
        continue;
      if (in != (k.side == TrimSide::kInside)) return false;
    }
    return true;
  };
  auto parametric_ok = [](const CellData& cd, Vec3 uvw) {
    for (const auto& k : cd.clauses)
      if (k.kind == TrimKind::kParametric && k.mesh->contains(uvw) != (k.side == TrimSide::kInside)) return false;
    return true;
  };
  st.seconds_inverse += lap(t);

  // Cells in scene order; a later cell with non-empty material overwrites an earlier one
  // (the paper's rule for the pixels on shared boundaries), and owns the pixel.
  for (std::size_t ci = 0; ci < cells_.size(); ++ci) {
    const CellData& cd = *cells_[ci];
    const Trivariate& tv = *trivariates_[static_cast<std::size_t>(cd.trivariate)];
    const bool trimmed = !cd.clauses.empty();
    const bool traced_first = tv.traced_first;
    std::optional<detail::CellTracer> tracer;
    if (!traced_first) {
      if (!tv.candidates(L, st.z_mm, 2.0 * outline_tolerance_mm_, segments, spans)) continue;
      if (cd.model_space_clauses && params_.model_space_narrowing) {
        // Only pixels that pass the volume and shell clauses are worth inverting: those
        // clauses are decided without this cell's inverse.
        for (int r = 0; r < L.height_px; ++r) {
          auto& row_spans = spans[static_cast<std::size_t>(r)];
          std::vector<std::pair<int, int>> kept_spans;
          for (const auto& [c0, c1] : row_spans)
            for (int col = c0; col <= c1; ++col) {
              if (!model_space_ok(cd, col, r)) continue;
              if (!kept_spans.empty() && kept_spans.back().second == col - 1)
                kept_spans.back().second = col;
              else
                kept_spans.push_back({col, col});
            }
          row_spans = std::move(kept_spans);
        }
      }
      if (cd.parametric_outlines && params_.parametric_outlines) {
        // Only pixels inside the outline of every "inside" parametric clause can pass it: the
        // even-odd interior of its cut at this layer, widened by the margin of every outline,
        // and every centre within the margin of the part of it within the margin above or
        // below the layer (a nearly flat face of the trim).
        const double margin = 2.0 * outline_tolerance_mm_;
        for (const auto& k : cd.clauses) {
          if (!k.outline) continue;
          k.outline->cut(st.z_mm, shell_segments);
          outline_segments.clear();
          for (const ShellSegment& s : shell_segments) outline_segments.push_back({s.x0, s.y0, s.x1, s.y1});
          detail::candidate_spans(outline_segments, L, margin, outline_spans);
          k.outline->slab(st.z_mm - margin, st.z_mm + margin, slab_triangles);
          detail::add_slab_spans(slab_triangles, st.z_mm - margin, st.z_mm + margin, L, margin, outline_spans);
          detail::merge_spans(outline_spans);
          detail::intersect_spans(spans, outline_spans);
        }
      }
      tracer.emplace(*tv.volume, tv.solver, params_, L.width_px, detail::CellTracer::kDefaultRowsInFlight,
                     tv.fold.has_value());
    }
    // The model-space clauses are tested on the inverted pixels where they did not choose them.
    const bool test_model_space = traced_first || (cd.model_space_clauses && !params_.model_space_narrowing);
    // Gives the cell's material to the inside pixels of one traced row.
    auto fill_row = [&](int r, const detail::TracedRow& traced) {
      const detail::TracedRow* row = &traced;
      if (trimmed && (test_model_space || cd.parametric_clauses)) {
        kept.cols.clear();
        kept.uvw.clear();
        kept.xyz.clear();
        for (std::size_t k = 0; k < row->cols.size(); ++k) {
          if (test_model_space && !model_space_ok(cd, row->cols[k], r)) continue;
          if (cd.parametric_clauses && !parametric_ok(cd, row->uvw[k])) continue;
          kept.cols.push_back(row->cols[k]);
          kept.uvw.push_back(row->uvw[k]);
          kept.xyz.push_back(row->xyz[k]);
        }
        row = &kept;
      }
      st.seconds_inverse += lap(t);
      const std::size_t n = row->cols.size();
      if (n == 0) return;
      // Every value is written by the material (MaterialFunction::evaluate_row).
      if (fractions.size() < n * static_cast<std::size_t>(m)) fractions.resize(n * static_cast<std::size_t>(m));
      // Scene cells carry their material already wrapped in the scene's fraction policy
      // (CheckedMaterial); the copy into the grid below checks what reaches the dithering.
      cd.cell->material->evaluate_row(row->uvw, row->xyz,
                                      std::span<float>(fractions).first(n * static_cast<std::size_t>(m)));
      // A traced row's columns increase: its span is its first and last.
      auto& [first_written, last_written] = buffers->written[static_cast<std::size_t>(r)];
      const bool row_unwritten = first_written > last_written;
      first_written = row_unwritten ? row->cols.front() : std::min(first_written, row->cols.front());
      last_written = row_unwritten ? row->cols.back() : std::max(last_written, row->cols.back());
      int fractions_ok = 1;
      for (std::size_t k = 0; k < n; ++k) {
        const int col = row->cols[k];
        const std::size_t at = static_cast<std::size_t>(r) * width + static_cast<std::size_t>(col);
        inside.at(col, r) = 1;
        const float* f = fractions.data() + k * static_cast<std::size_t>(m);
        float sum = 0.0f;
        for (int j = 0; j < m; ++j) sum += f[j];
        if (sum <= 0.0f) {
          if (several_cells && !owner_gave_material[at]) owner[at] = static_cast<int>(ci);
          continue;
        }
        if (several_cells) {
          owner[at] = static_cast<int>(ci);
          owner_gave_material[at] = 1;
        }
        float* px = grid.pixel(col, r).data();
        for (int j = 0; j < m; ++j) {
          px[j] = f[j];
          fractions_ok &= static_cast<int>(f[j] >= fraction_lo) & static_cast<int>(f[j] <= fraction_hi);
        }
        fractions_ok &= static_cast<int>(sum <= fraction_hi);
      }
      // The grid is checked as it is written, not again by the dithering (dither_checked_grid).
      if (!fractions_ok)
        for (int col : row->cols) grid.check_pixel(col, r, dither_.fraction_tolerance);
      st.seconds_material += lap(t);
    };
    if (traced_first) {
      const auto& rows = trims.rows[static_cast<std::size_t>(cd.trivariate)];
      for (int r = 0; r < L.height_px; ++r) fill_row(r, rows[static_cast<std::size_t>(r)]);
    } else {
      tracer->trace_layer(L, st.z_mm, spans, fill_row);
      counters += tracer->counters();
    }
  }

  st.seconds_inverse += lap(t);
  detail::dither_checked_grid(grid, inside, dither_, result.labels, layer);
  st.seconds_dither = lap(t);
  st.voxels_per_material.assign(static_cast<std::size_t>(m), 0);
  // Outside the written spans every pixel is outside and void.
  std::vector<std::int64_t> per_label(static_cast<std::size_t>(m) + 1, 0);
  for (int r = 0; r < L.height_px; ++r) {
    const auto [first, last] = buffers->written[static_cast<std::size_t>(r)];
    const std::uint8_t* labels = result.labels.row(r).data();
    const std::uint8_t* in = inside.row(r).data();
    for (int col = first; col <= last; ++col) {
      ++per_label[labels[col]];
      st.pixels_inside += in[col];
    }
  }
  for (int j = 0; j < m; ++j)
    st.voxels_per_material[static_cast<std::size_t>(j)] = per_label[static_cast<std::size_t>(j) + 1];
  st.pixels_per_cell.assign(cells_.size(), 0);
  if (several_cells) {
    for (int o : owner)
      if (o >= 0) ++st.pixels_per_cell[static_cast<std::size_t>(o)];
  } else {
    if (!cells_.empty()) st.pixels_per_cell[0] = st.pixels_inside;
    if (owner_out) {
      owner.resize(static_cast<std::size_t>(st.pixels_total));
      std::transform(inside.values().begin(), inside.values().end(), owner.begin(),
                     [](std::uint8_t in) { return in != 0 ? 0 : -1; });
    }
  }
  st.candidates = counters.candidates;
  st.global_calls = counters.global_calls;
  st.global_unseeded = counters.global_unseeded;
  st.newton_evals = counters.newton_evals;
  st.guesses = counters.guesses;
  st.guess_misses = counters.guess_misses;
  st.jacobian_steps = counters.jacobian_steps;
  st.slow_path_pixels = counters.slow_path;
  st.folded_pixels = counters.folded;
  st.unresolved_pixels = counters.unresolved;
  if (owner_out) *owner_out = std::move(owner);
  give_back(std::move(buffers));
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace trivox
