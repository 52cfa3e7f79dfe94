#include "trivox/trim/detail/shell_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "trim/trimmed_tessellation.h"
#include "trivox/error.h"

namespace trivox {

std::string_view to_string(TrimSide s) noexcept { return s == TrimSide::kInside ? "inside" : "outside"; }

std::string_view to_string(TrimKind k) noexcept {
  switch (k) {
    case TrimKind::kVolume: return "volume";
    case TrimKind::kShell: return "shell";
    case TrimKind::kParametric: return "parametric";
  }
  return "?";
}

namespace {

double sample(double lo, double hi, int i, int n) { return i == n - 1 ? hi : lo + (hi - lo) * i / (n - 1); }

using Map = std::function<Vec3(Vec3)>;

// Largest deviations of the surface from its bilinear grid cells, at the cells' centres: of
// the surface itself, and of its image through `map` (when given) from the bilinear cell of
// the mapped corners.
std::pair<double, double> deviation(const TensorSpline& s, int n, const Map* map) {
  double worst = 0, worst_mapped = 0;
  std::vector<Vec3> prev(static_cast<std::size_t>(n)), cur(static_cast<std::size_t>(n));
  std::vector<Vec3> prev_m(static_cast<std::size_t>(map ? n : 0)), cur_m(static_cast<std::size_t>(map ? n : 0));
  const double a0 = s.lo(0), a1 = s.hi(0), b0 = s.lo(1), b1 = s.hi(1);
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    prev[k] = detail::surface_point(s, sample(a0, a1, i, n), b0);
    if (map) prev_m[k] = (*map)(prev[k]);
  }
  for (int j = 1; j < n; ++j) {
    const double tb = sample(b0, b1, j, n), tb_prev = sample(b0, b1, j - 1, n);
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      cur[k] = detail::surface_point(s, sample(a0, a1, i, n), tb);
      if (map) cur_m[k] = (*map)(cur[k]);
    }
    for (int i = 1; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Vec3 bilinear = 0.25 * (prev[k - 1] + prev[k] + cur[k - 1] + cur[k]);
      const Vec3 centre =
          detail::surface_point(s, 0.5 * (sample(a0, a1, i - 1, n) + sample(a0, a1, i, n)), 0.5 * (tb_prev + tb));
      // The triangles split the cell along its (k-1, j-1)-(k, j) diagonal: a twisted cell
      // can match its bilinear patch at the centre and miss the triangles, so the diagonal's
      // midpoint is checked too.
      worst = std::max({worst, norm(centre - bilinear), norm(centre - 0.5 * (prev[k - 1] + cur[k]))});
      if (map) {
        const Vec3 mc = (*map)(centre);
        const Vec3 mb = 0.25 * (prev_m[k - 1] + prev_m[k] + cur_m[k - 1] + cur_m[k]);
        // The mapped edge midpoints too: a map that bends a straight edge moves the outline
        // where neighbouring cells meet.
        const Vec3 e0 = (*map)(0.5 * (prev[k - 1] + prev[k])), e1 = (*map)(0.5 * (prev[k - 1] + cur[k - 1]));
        worst_mapped =
            std::max({worst_mapped, norm(mc - mb), norm(mc - 0.5 * (prev_m[k - 1] + cur_m[k])),
                      norm(e0 - 0.5 * (prev_m[k - 1] + prev_m[k])), norm(e1 - 0.5 * (prev_m[k - 1] + cur_m[k - 1]))});
      }
    }
    std::swap(prev, cur);
    std::swap(prev_m, cur_m);
  }
  return {worst, worst_mapped};
}

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const noexcept {
    return static_cast<std::size_t>(k.x * 73856093LL ^ k.y * 19349663LL ^ k.z * 83492791LL);
  }
};

}  // namespace

ShellMesh::ShellMesh(const TrimShell& shell, double tolerance, int max_samples)
    : ShellMesh(shell, tolerance, nullptr, 0.0, max_samples) {}

ShellMesh::ShellMesh(const TrimShell& shell, double tolerance, const std::function<Vec3(Vec3)>& map,
                     double map_tolerance, int max_samples) {
  const Map* mapping = map ? &map : nullptr;
  if (shell.mesh) {
    // A mesh trim is taken as it is: there is nothing to sample, and no map refines it.
    if (mapping != nullptr)
      throw ModelError(
          fmt::format("{}: a triangle mesh trims in model space, not in a volume's parameters", shell.name));
    build_mesh_trim(*shell.mesh, shell.rule);
    return;
  }
  if (shell.surfaces.empty() && shell.trimmed.empty())
    throw ModelError(fmt::format("{}: the shell has no surface", shell.name));
  if (!shell.trimmed.empty()) {
    build_trimmed(shell, tolerance, mapping, map_tolerance, max_samples);
    return;
  }
  int n = 3;
  for (std::size_t i = 0; i < shell.surfaces.size(); ++i) {
    const TensorSpline& s = shell.surfaces[i];
    if (s.param_dim() != 2 || s.point_dim() != 3)
      throw ModelError(
          fmt::format("{}: surface {} has {} parameter(s) and {} coordinate(s); a shell takes "
                      "surfaces in space (2 and 3)",
                      shell.name, i, s.param_dim(), s.point_dim()));
    for (int d = 0; d < 2; ++d) n = std::max(n, 2 * (static_cast<int>(s.knots(d).interior_breaks().size()) + 1) + 1);
  }
  // One sample count for every surface and direction keeps shared edges sampled alike.
  n = std::min(n, max_samples);
  while (n < max_samples) {
    double worst = 0, worst_mapped = 0;
    for (const TensorSpline& s : shell.surfaces) {
      const auto [d, dm] = deviation(s, n, mapping);
      worst = std::max(worst, d);
      worst_mapped = std::max(worst_mapped, dm);
    }
    if (worst <= tolerance && worst_mapped <= map_tolerance) break;
    n = std::min(max_samples, 2 * n - 1);
  }
  samples_ = n;

  // Samples, then the weld: a hash of cells of the weld distance, looking at the 27 cells
  // around each new point so that two points on either side of a cell wall still merge.
  std::vector<Vec3> raw, vertices;
  std::vector<SlicedMesh::Triangle> triangles;
  Box3 bounds;
  for (const TensorSpline& s : shell.surfaces)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 p = detail::surface_point(s, sample(s.lo(0), s.hi(0), i, n), sample(s.lo(1), s.hi(1), j, n));
        raw.push_back(p);
        bounds.expand(p);
      }
  const double size = norm(bounds.hi - bounds.lo);
  const double weld = std::max(1e-9 * size, 1e-12);
  std::unordered_map<CellKey, std::vector<int>, CellHash> cells;
  std::vector<int> index(raw.size());
  for (std::size_t k = 0; k < raw.size(); ++k) {
    const Vec3& p = raw[k];
    const CellKey key{static_cast<std::int64_t>(std::floor(p.x / weld)),
                      static_cast<std::int64_t>(std::floor(p.y / weld)),
                      static_cast<std::int64_t>(std::floor(p.z / weld))};
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx)
      for (int dy = -1; dy <= 1 && found < 0; ++dy)
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          const auto it = cells.find({key.x + dx, key.y + dy, key.z + dz});
          if (it == cells.end()) continue;
          for (int v : it->second)
            if (norm(vertices[static_cast<std::size_t>(v)] - p) <= weld) {
              found = v;
              break;
            }
        }
    if (found < 0) {
      found = static_cast<int>(vertices.size());
      vertices.push_back(p);
      cells[key].push_back(found);
    }
    index[k] = found;
  }
  const auto un = static_cast<std::size_t>(n);
  for (std::size_t s = 0; s < shell.surfaces.size(); ++s)
    for (std::size_t j = 0; j + 1 < un; ++j)
      for (std::size_t i = 0; i + 1 < un; ++i) {
        const std::size_t base = s * un * un;
        const int a = index[base + j * un + i], b = index[base + j * un + i + 1];
        const int c = index[base + (j + 1) * un + i + 1], d = index[base + (j + 1) * un + i];
        // Triangles that collapsed in the weld (a pole of a surface) carry no area.
        for (const std::array<int, 3> t : {std::array<int, 3>{a, b, c}, std::array<int, 3>{a, c, d}})
          if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
      }
  build_index(std::move(vertices), std::move(triangles));
  open_edges_ = mesh_.odd_edges();
}

void ShellMesh::build_trimmed(const TrimShell& shell, double tolerance, const std::function<Vec3(Vec3)>* map,
                              double map_tolerance, int max_samples) {
  gap_tolerant_ = true;
  std::vector<const TensorSpline*> all;
  for (const TensorSpline& s : shell.surfaces) all.push_back(&s);
  for (const TrimmedSurface& t : shell.trimmed) all.push_back(&t.surface);
  for (const TensorSpline* s : all)
    if (s->param_dim() != 2 || s->point_dim() != 3)
      throw ModelError(
          fmt::format("{}: a surface has {} parameter(s) and {} coordinate(s); a shell takes surfaces in "
                      "space (2 and 3)",
                      shell.name, s->param_dim(), s->point_dim()));
  // One sample count for all, as for a welded shell (the seams share no vertices here).
  int n = 3;
  for (const TensorSpline* s : all)
    for (int d = 0; d < 2; ++d) n = std::max(n, 2 * (static_cast<int>(s->knots(d).interior_breaks().size()) + 1) + 1);
  n = std::min(n, max_samples);
  while (n < max_samples) {
    double worst = 0, worst_mapped = 0;
    for (const TensorSpline* s : all) {
      const auto [d, dm] = deviation(*s, n, map);
      worst = std::max(worst, d);
      worst_mapped = std::max(worst_mapped, dm);
    }
    if (worst <= tolerance && worst_mapped <= map_tolerance) break;
    n = std::min(max_samples, 2 * n - 1);
  }
  samples_ = n;
  std::vector<Vec3> vertices;
  std::vector<SlicedMesh::Triangle> triangles;
  for (const TensorSpline& s : shell.surfaces) {
    const TrimmedSurface whole{shell.name, s, {}};
    detail::tessellate_trimmed(whole, n, vertices, triangles);
  }
  for (const TrimmedSurface& t : shell.trimmed) detail::tessellate_trimmed(t, n, vertices, triangles);
  build_index(std::move(vertices), std::move(triangles));
  seam_gap_ = detail::check_trimmed_closed(shell, 1e-3 * norm(bounds().hi - bounds().lo));
}

ShellMesh ShellMesh::mapped(const std::function<Vec3(Vec3)>& map) const {
  ShellMesh m;
  m.samples_ = samples_;
  m.open_edges_ = open_edges_;
  m.gap_tolerant_ = gap_tolerant_;
  m.seam_gap_ = seam_gap_;
  m.winding_ = winding_;
  m.flipped_ = flipped_;
  m.own_triangles_ = own_triangles_;
  m.cones_ = cones_;
  const SlicedMesh moved = mesh_.mapped(map);
  m.build_index(moved.vertices(), moved.triangles());
  m.bound_cones();
  return m;
}

namespace {

// floor(v) clamped to [0, n - 1], safe for any v (compared as a double before the cast).
int clamped_floor(double v, int n) noexcept {
  const double f = std::floor(v);
  if (!(f > 0)) return 0;
  return f >= n - 1 ? n - 1 : static_cast<int>(f);
}

}  // namespace

void ShellMesh::build_index(std::vector<Vec3> vertices, std::vector<SlicedMesh::Triangle> triangles) {
  mesh_ = SlicedMesh(std::move(vertices), std::move(triangles));
  yz_cells_.clear();
  const Box3& b = mesh_.bounds();
  if (mesh_.empty() || b.empty()) return;
  ny_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(mesh_.triangle_count()) / 4.0)), 1, 1024);
  z0_ = b.lo.z;
  dzc_ = std::max((b.hi.z - b.lo.z) / ny_, 1e-300);
  y0_ = b.lo.y;
  dy_ = std::max((b.hi.y - b.lo.y) / ny_, 1e-300);
  yz_cells_.resize(static_cast<std::size_t>(ny_) * static_cast<std::size_t>(ny_));
  const auto& verts = mesh_.vertices();
  const auto& tris = mesh_.triangles();
  for (std::size_t k = 0; k < tris.size(); ++k) {
    Box3 t;
    for (int v : tris[k]) t.expand(verts[static_cast<std::size_t>(v)]);
    for (int iz = clamped_floor((t.lo.z - z0_) / dzc_, ny_); iz <= clamped_floor((t.hi.z - z0_) / dzc_, ny_); ++iz)
      for (int iy = clamped_floor((t.lo.y - y0_) / dy_, ny_); iy <= clamped_floor((t.hi.y - y0_) / dy_, ny_); ++iy)
        yz_cells_[static_cast<std::size_t>(iz) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(iy)]
            .push_back(static_cast<int>(k));
  }
}

std::size_t ShellMesh::yz_cell(double y, double z) const noexcept {
  return static_cast<std::size_t>(clamped_floor((z - z0_) / dzc_, ny_)) * static_cast<std::size_t>(ny_) +
         static_cast<std::size_t>(clamped_floor((y - y0_) / dy_, ny_));
}

bool ShellMesh::line_parity(Vec3 p, double dx, double dy, bool& even) const {
  int beyond = 0, total = 0;
  Segment2 s;
  for (int tri : mesh_.near(p.z)) {
    if (!mesh_.cut_triangle(tri, p.z, s)) continue;
    // Signed distances from the line, with the tie rule "on the line counts as above".
    const double s0 = -dy * (s.x0 - p.x) + dx * (s.y0 - p.y), s1 = -dy * (s.x1 - p.x) + dx * (s.y1 - p.y);
    if ((s0 >= 0) == (s1 >= 0)) continue;
    const double f = s0 / (s0 - s1);
    const double t = dx * (s.x0 + f * (s.x1 - s.x0) - p.x) + dy * (s.y0 + f * (s.y1 - s.y0) - p.y);
    ++total;
    if (t > 0) ++beyond;
  }
  even = total % 2 == 0;
  return beyond % 2 == 1;
}

void ShellMesh::row_crossings(Vec3 p, int& beyond, int& winding) const {
  beyond = winding = 0;
  const Box3& b = bounds();
  if (yz_cells_.empty() || !(p.z >= b.lo.z && p.z <= b.hi.z && p.y >= b.lo.y && p.y <= b.hi.y)) return;
  Segment2 s;
  int direction;
  double x;
  for (int tri : yz_cells_[yz_cell(p.y, p.z)])
    if (mesh_.cut_triangle(tri, p.z, s, direction) && crosses_row(s, p.y, x) && x > p.x) {
      ++beyond;
      winding += crossing_winding(s, direction);
    }
}

bool ShellMesh::contains(Vec3 p) const {
  if (winding_) {
    int beyond, w;
    row_crossings(p, beyond, w);
    return winding_inside(w, p);
  }
  const Box3& b = bounds();
  if (gap_tolerant_) {
    if (yz_cells_.empty() ||
        !(p.z >= b.lo.z && p.z <= b.hi.z && p.y >= b.lo.y && p.y <= b.hi.y && p.x >= b.lo.x && p.x <= b.hi.x))
      return false;
    // Along x by the rule of the rows (crosses_row), then y and the diagonals.
    int beyond = 0, total = 0;
    Segment2 s;
    double x;
    for (int tri : yz_cells_[yz_cell(p.y, p.z)])
      if (mesh_.cut_triangle(tri, p.z, s) && crosses_row(s, p.y, x)) {
        ++total;
        if (x > p.x) ++beyond;
      }
    if (total % 2 == 0) return beyond % 2 == 1;
    const double h = std::sqrt(0.5);
    for (const auto& [dx, dy] : {std::pair{0.0, 1.0}, std::pair{h, h}, std::pair{h, -h}}) {
      bool even = false;
      const bool in = line_parity(p, dx, dy, even);
      if (even) return in;
    }
    return beyond % 2 == 1;
  }
  if (yz_cells_.empty() || !(p.z >= b.lo.z && p.z <= b.hi.z && p.y >= b.lo.y && p.y <= b.hi.y) || p.x > b.hi.x)
    return false;
  bool inside = false;
  Segment2 s;
  double x;
  for (int tri : yz_cells_[yz_cell(p.y, p.z)])
    if (mesh_.cut_triangle(tri, p.z, s) && crosses_row(s, p.y, x) && x > p.x) inside = !inside;
  return inside;
}

}  // namespace trivox
