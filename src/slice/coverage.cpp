#include "coverage.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "boundary_mesh.h"
#include "cell_preparation.h"
#include "scanline.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/trim/detail/shell_mesh.h"

namespace trivox::detail {

void grey_source_row(const MaterialFunction& source, const TracedRow& row, std::span<const float> fractions, int m,
                     int r, int width_px, std::span<float> values, std::vector<float>& scratch) {
  const std::size_t n = row.cols.size();
  if (n == 0) return;
  if (scratch.size() < n) scratch.resize(n);
  source.evaluate_row(row.uvw, row.xyz, std::span<float>(scratch).first(n));
  const auto mm = static_cast<std::size_t>(m);
  for (std::size_t k = 0; k < n; ++k) {
    float sum = 0.0f;
    for (std::size_t j = 0; j < mm; ++j) sum += fractions[k * mm + j];
    // Only where the cell gives material, as the grid is written: a later cell with material
    // overwrites, a later void one does not.
    if (sum > 0.0f)
      values[static_cast<std::size_t>(r) * static_cast<std::size_t>(width_px) + static_cast<std::size_t>(row.cols[k])] =
          scratch[k];
  }
}

GreyImage grey_from_grid(const MaterialGrid& grid, const std::vector<std::pair<int, int>>& written,
                         const GreyscaleDef& greyscale, std::span<const float> values) {
  GreyImage grey(grid.width_px(), grid.height_px(), 0);
  const int m = grid.num_materials();
  for (int r = 0; r < grid.height_px(); ++r) {
    const auto [first, last] = written[static_cast<std::size_t>(r)];
    for (int col = first; col <= last; ++col) {
      const std::span<const float> f = grid.pixel(col, r);
      float sum = 0.0f;
      for (int j = 0; j < m; ++j) sum += f[static_cast<std::size_t>(j)];
      if (!(sum > 0.0f)) continue;
      const double value =
          greyscale.material >= 0
              ? static_cast<double>(f[static_cast<std::size_t>(greyscale.material)])
              : static_cast<double>(values[static_cast<std::size_t>(r) * static_cast<std::size_t>(grid.width_px()) +
                                           static_cast<std::size_t>(col)]);
      grey.at(col, r) = greyscale.curve.level(value);
    }
  }
  return grey;
}

struct EdgeCoverage::Trivariate {
  const Volume* volume;
  SlicedMesh mesh;  // the outline mesh at the sub-sample grid's tolerance (boundary_mesh.h)
  GlobalSolver solver;
  // Within a fixed budget (as the slicer's outline meshes are within theirs); a mesh the
  // budget cuts short is accepted here: a sub-sample it misjudges near the edge moves an
  // edge pixel's grey level by one sub-sample.
  Trivariate(const Volume& v, double tolerance_mm, const std::atomic<bool>* stop)
      : volume(&v), mesh(build_boundary_mesh(v, tolerance_mm, std::int64_t{1} << 22, stop).mesh), solver(v) {}
};

struct EdgeCoverage::CellData {
  struct Clause {
    TrimKind kind;
    TrimSide side;
    int trivariate = -1;                       // kVolume
    std::shared_ptr<const ShellMesh> mesh;     // kShell (model space), kParametric (u, v, w)
    std::shared_ptr<const ShellMesh> outline;  // kParametric: mesh mapped through the cell's volume
    int shell_slot = -1;                       // kShell
  };
  const Cell* cell = nullptr;
  int trivariate = -1;
  std::vector<Clause> clauses;
};

EdgeCoverage::EdgeCoverage(const Scene& scene, const SliceParams& params, const SliceLayout& layout)
    : scene_(scene), params_(params), layout_(layout) {
  if (!scene.greyscale) throw Error("edge coverage needs a scene with a greyscale block");
  k_ = scene.greyscale->antialiasing;
  if (k_ < 2 || k_ > 8) throw Error(fmt::format("edge coverage: {} x {} sub-samples; k is 2 to 8", k_, k_));
  fine_ = layout;
  fine_.pitch_x_mm = layout.pitch_x_mm / k_;
  fine_.pitch_y_mm = layout.pitch_y_mm / k_;
  fine_.width_px = layout.width_px * k_;
  fine_.height_px = layout.height_px * k_;
  // As the slicer's outlines are to the pixels (an eighth of the finest pitch), so these are
  // to the sub-samples.
  tolerance_mm_ = 0.125 * std::min({fine_.pitch_x_mm, fine_.pitch_y_mm, layout.layer_mm});
  const TrivariatePlan plan = plan_trivariates(scene);
  for (const TrivariatePlan::Trivariate& t : plan.trivariates)
    trivariates_.push_back(std::make_unique<Trivariate>(*t.volume, tolerance_mm_, params.stop));
  // The same tessellations of the trim shells as the slicer's, at this grid's tolerance.
  TrimShellMeshes shells(0.5 * tolerance_mm_, tolerance_mm_);
  for (std::size_t i = 0; i < scene.cells.size(); ++i) {
    const Cell& c = scene.cells[i];
    auto cd = std::make_unique<CellData>();
    cd->cell = &c;
    cd->trivariate = plan.of_cell[i];
    for (std::size_t j = 0; j < c.trim.clauses.size(); ++j) {
      const TrimClause& clause = c.trim.clauses[j];
      CellData::Clause k{clause.kind, clause.side, -1, nullptr, nullptr, -1};
      if (clause.kind == TrimKind::kVolume) {
        k.trivariate = plan.of_clause[i][j];
      } else {
        k.mesh = shells.mesh(c, clause);
        if (clause.kind == TrimKind::kParametric)
          k.outline = shells.outline(c, clause);
        else
          k.shell_slot = shell_slots_++;
      }
      cd->clauses.push_back(std::move(k));
    }
    cells_.push_back(std::move(cd));
  }
}

EdgeCoverage::~EdgeCoverage() = default;

namespace {

// Marks every pixel of `L` whose square, widened by `margin` on each side, meets segment s.
void mark_band(const Segment2& s, const SliceLayout& L, double margin, std::vector<std::uint8_t>& band) {
  const double hx = 0.5 * L.pitch_x_mm + margin, hy = 0.5 * L.pitch_y_mm + margin;
  const double ylo = std::min(s.y0, s.y1), yhi = std::max(s.y0, s.y1);
  const int r0 = std::max(0, static_cast<int>(std::ceil(L.row_of_y(yhi + hy))));
  const int r1 = std::min(L.height_px - 1, static_cast<int>(std::floor(L.row_of_y(ylo - hy))));
  for (int r = r0; r <= r1; ++r) {
    const double yc = L.y_of_row(r);
    // The part of the segment within the row's widened strip [yc - hy, yc + hy].
    double xa, xb;
    if (s.y0 == s.y1) {
      xa = std::min(s.x0, s.x1);
      xb = std::max(s.x0, s.x1);
    } else {
      double t0 = (yc - hy - s.y0) / (s.y1 - s.y0), t1 = (yc + hy - s.y0) / (s.y1 - s.y0);
      if (t0 > t1) std::swap(t0, t1);
      t0 = std::clamp(t0, 0.0, 1.0);
      t1 = std::clamp(t1, 0.0, 1.0);
      if (t0 > t1) continue;
      const double x0 = s.x0 + t0 * (s.x1 - s.x0), x1 = s.x0 + t1 * (s.x1 - s.x0);
      xa = std::min(x0, x1);
      xb = std::max(x0, x1);
    }
    const int c0 = std::max(0, static_cast<int>(std::ceil(L.col_of_x(xa - hx))));
    const int c1 = std::min(L.width_px - 1, static_cast<int>(std::floor(L.col_of_x(xb + hx))));
    for (int c = c0; c <= c1; ++c)
      band[static_cast<std::size_t>(r) * static_cast<std::size_t>(L.width_px) + static_cast<std::size_t>(c)] = 1;
  }
}

}  // namespace

std::int64_t EdgeCoverage::antialias(int layer, GreyImage& grey) const {
  const SliceLayout& L = layout_;
  const SliceLayout& F = fine_;
  const double z = L.z_of_layer(layer);
  const double margin = 2.0 * tolerance_mm_;
  const auto width = static_cast<std::size_t>(L.width_px);

  // 1. The edge pixels: near the cut of any outline.
  std::vector<std::vector<Segment2>> cuts(trivariates_.size());
  std::vector<std::vector<Segment2>> shell_cuts(static_cast<std::size_t>(shell_slots_));
  std::vector<std::uint8_t> in_band(width * static_cast<std::size_t>(L.height_px), 0);
  for (std::size_t t = 0; t < trivariates_.size(); ++t) {
    trivariates_[t]->mesh.cut(z, cuts[t]);
    for (const Segment2& s : cuts[t]) mark_band(s, L, margin, in_band);
  }
  std::vector<Segment2> shell_segments;
  for (const auto& cd : cells_)
    for (const auto& k : cd->clauses) {
      const ShellMesh* outline = k.shell_slot >= 0 ? k.mesh.get() : k.outline.get();
      if (outline == nullptr) continue;
      outline->mesh().cut(z, shell_segments);
      if (k.shell_slot >= 0) shell_cuts[static_cast<std::size_t>(k.shell_slot)] = shell_segments;
      for (const Segment2& s : shell_segments) mark_band(s, L, margin, in_band);
    }
  std::vector<int> band_index(in_band.size(), -1);
  std::vector<std::pair<int, int>> band;  // (col, row), row-major
  for (int r = 0; r < L.height_px; ++r)
    for (int c = 0; c < L.width_px; ++c) {
      const std::size_t at = static_cast<std::size_t>(r) * width + static_cast<std::size_t>(c);
      if (!in_band[at]) continue;
      band_index[at] = static_cast<int>(band.size());
      band.push_back({c, r});
    }
  if (band.empty()) return 0;

  // 2. Their sub-samples, as spans of the fine grid.
  const int k = k_;
  RowSpans band_spans(static_cast<std::size_t>(F.height_px));
  for (int r = 0; r < L.height_px; ++r) {
    int c = 0;
    while (c < L.width_px) {
      if (!in_band[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(c)]) {
        ++c;
        continue;
      }
      int e = c;
      while (e + 1 < L.width_px && in_band[static_cast<std::size_t>(r) * width + static_cast<std::size_t>(e + 1)]) ++e;
      for (int i = 0; i < k; ++i) band_spans[static_cast<std::size_t>(r * k + i)].push_back({c * k, e * k + k - 1});
      c = e + 1;
    }
  }

  // 3. Every trivariate traced on them (within its outline's candidates).
  std::vector<std::vector<TracedRow>> traced(trivariates_.size());
  RowSpans spans;
  for (std::size_t t = 0; t < trivariates_.size(); ++t) {
    if (cuts[t].empty()) continue;
    const Trivariate& tv = *trivariates_[t];
    candidate_spans(cuts[t], F, margin, spans);
    intersect_spans(spans, band_spans);
    traced[t].resize(static_cast<std::size_t>(F.height_px));
    CellTracer tracer(*tv.volume, tv.solver, params_, F.width_px);
    tracer.trace_layer(F, z, spans, [&](int r, const TracedRow& row) { traced[t][static_cast<std::size_t>(r)] = row; });
  }
  std::vector<std::vector<std::vector<double>>> shell_rows(static_cast<std::size_t>(shell_slots_));
  for (std::size_t s = 0; s < shell_rows.size(); ++s) shell_row_crossings(shell_cuts[s], F, shell_rows[s]);
  auto traced_inside = [&](int t, int r, int col) {
    const auto& rows = traced[static_cast<std::size_t>(t)];
    if (rows.empty()) return false;
    const auto& cols = rows[static_cast<std::size_t>(r)].cols;
    return std::binary_search(cols.begin(), cols.end(), col);
  };

  // 4. The grey of every sub-sample: the last cell in scene order that gives it material.
  const GreyscaleDef& g = *scene_.greyscale;
  const int m = scene_.num_materials();
  const auto kk = static_cast<std::size_t>(k) * static_cast<std::size_t>(k);
  std::vector<double> sub(band.size() * kk, 0.0);
  TracedRow kept;
  std::vector<float> fractions, values;
  for (const auto& cd : cells_) {
    const auto& rows = traced[static_cast<std::size_t>(cd->trivariate)];
    if (rows.empty()) continue;
    for (int r = 0; r < F.height_px; ++r) {
      const TracedRow& row = rows[static_cast<std::size_t>(r)];
      kept.cols.clear();
      kept.uvw.clear();
      kept.xyz.clear();
      for (std::size_t i = 0; i < row.cols.size(); ++i) {
        const int col = row.cols[i];
        bool ok = true;
        for (const auto& clause : cd->clauses) {
          bool in = true;
          if (clause.kind == TrimKind::kVolume) {
            in = traced_inside(clause.trivariate, r, col);
          } else if (clause.kind == TrimKind::kShell) {
            const auto& xs = shell_rows[static_cast<std::size_t>(clause.shell_slot)][static_cast<std::size_t>(r)];
            // A mesh trim by the winding-number rule asks the mesh, sub-sample by sub-sample.
            in = clause.mesh->winding() || (clause.mesh->gap_tolerant() && xs.size() % 2 == 1)
                     ? clause.mesh->contains(row.xyz[i])
                     : inside_crossings(xs, F.x_of_col(col));
          } else {
            in = clause.mesh->contains(row.uvw[i]);
          }
          if (in != (clause.side == TrimSide::kInside)) {
            ok = false;
            break;
          }
        }
        if (!ok) continue;
        kept.cols.push_back(col);
        kept.uvw.push_back(row.uvw[i]);
        kept.xyz.push_back(row.xyz[i]);
      }
      const std::size_t n = kept.cols.size();
      if (n == 0) continue;
      fractions.resize(n * static_cast<std::size_t>(m));
      cd->cell->material->evaluate_row(kept.uvw, kept.xyz, fractions);
      if (cd->cell->grey_source) {
        values.resize(n);
        cd->cell->grey_source->evaluate_row(kept.uvw, kept.xyz, values);
      }
      for (std::size_t i = 0; i < n; ++i) {
        const float* f = fractions.data() + i * static_cast<std::size_t>(m);
        float sum = 0.0f;
        for (int j = 0; j < m; ++j) sum += f[j];
        if (!(sum > 0.0f)) continue;
        const double value = g.material >= 0 ? static_cast<double>(f[g.material]) : static_cast<double>(values[i]);
        const int col = kept.cols[i];
        const std::size_t b = static_cast<std::size_t>(
            band_index[static_cast<std::size_t>(r / k) * width + static_cast<std::size_t>(col / k)]);
        sub[b * kk + static_cast<std::size_t>(r % k) * static_cast<std::size_t>(k) +
            static_cast<std::size_t>(col % k)] = g.curve.grey(value);
      }
    }
  }

  // 5. Each edge pixel: the mean of its sub-samples (0 where no cell gives material).
  for (std::size_t b = 0; b < band.size(); ++b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < kk; ++i) sum += sub[b * kk + i];
    grey.at(band[b].first, band[b].second) = GreyCalibration::round_level(sum / static_cast<double>(kk));
  }
  return static_cast<std::int64_t>(band.size());
}

}  // namespace trivox::detail
