#include "boundary_mesh.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "trivox/cancel.h"
#include "trivox/error.h"

namespace trivox::detail {

namespace {

std::vector<double> samples_of(double lo, double hi, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t[static_cast<std::size_t>(i)] = i == n - 1 ? hi : lo + (hi - lo) * i / (n - 1);
  return t;
}

void throw_if_stopped(const std::atomic<bool>* stop) {
  trivox::throw_if_stopped(stop, "building a cell's outline mesh");
}

// Largest deviation between a face's surface and its bilinear grid cells, checked at cell
// centres, for the face where direction `fixed` is at `at`; `a` and `b` are the other two.
// The stop flag is read for every row of samples: a face of a high-order volume at its finest
// may take seconds.
double face_deviation(const Volume& v, int fixed, double at, int a, const std::vector<double>& ta, int b,
                      const std::vector<double>& tb, const std::atomic<bool>* stop) {
  double worst = 0.0;
  auto param = [&](double s, double t) {
    Vec3 p;
    p[fixed] = at;
    p[a] = s;
    p[b] = t;
    return p;
  };
  // A row of grid points, and of cell centres, evaluated together.
  const std::size_t n = ta.size();
  std::vector<Vec3> row_params(n), centre_params(n - 1), prev(n), cur(n), centres(n - 1);
  auto grid_row = [&](double t, std::vector<Vec3>& out) {
    for (std::size_t i = 0; i < n; ++i) row_params[i] = param(ta[i], t);
    v.evaluate_many(row_params, out);
  };
  grid_row(tb[0], prev);
  for (std::size_t j = 1; j < tb.size(); ++j) {
    throw_if_stopped(stop);
    grid_row(tb[j], cur);
    for (std::size_t i = 1; i < n; ++i)
      centre_params[i - 1] = param(0.5 * (ta[i - 1] + ta[i]), 0.5 * (tb[j - 1] + tb[j]));
    v.evaluate_many(centre_params, centres);
    for (std::size_t i = 1; i < n; ++i) {
      const Vec3 bilinear = 0.25 * (prev[i - 1] + prev[i] + cur[i - 1] + cur[i]);
      const Vec3 centre = centres[i - 1];
      // The cell is drawn as two triangles split along its (i-1, j-1)-(i, j) diagonal: a
      // twisted cell can match its bilinear patch at the centre and still miss the
      // triangles by far, so the diagonal's midpoint is checked too.
      worst = std::max({worst, norm(centre - bilinear), norm(centre - 0.5 * (prev[i - 1] + cur[i]))});
    }
    std::swap(prev, cur);
  }
  return worst;
}

}  // namespace

std::int64_t boundary_mesh_vertices(const std::array<int, 3>& n) noexcept {
  const std::int64_t a = n[0], b = n[1], c = n[2];
  return 2 * (a * b + b * c + c * a);
}

BoundaryMesh build_boundary_mesh(const Volume& v, double tolerance_mm, std::int64_t max_vertices,
                                 const std::atomic<bool>* stop) {
  const ParamBox& dom = v.domain();
  std::array<int, 3> n{};
  // Start from a few samples per polynomial piece and double where a face is too coarse.
  for (int d = 0; d < 3; ++d)
    n[static_cast<std::size_t>(d)] =
        std::max(3, 2 * (static_cast<int>(v.spline().knots(d).interior_breaks().size()) + 1) + 1);
  // A volume of very many pieces starts coarser, within the budget (2 samples at least).
  while (boundary_mesh_vertices(n) > max_vertices) {
    auto most = std::max_element(n.begin(), n.end());
    if (*most <= 2) break;
    *most = std::max(2, *most / 2 + 1);
  }
  constexpr int kMaxSamples = 4096;
  double deviation = 0;
  for (;;) {  // at most 12 rounds: a direction doubles from 3 to kMaxSamples in 11
    throw_if_stopped(stop);
    std::array<std::vector<double>, 3> t;
    for (int d = 0; d < 3; ++d)
      t[static_cast<std::size_t>(d)] = samples_of(dom.lo[d], dom.hi[d], n[static_cast<std::size_t>(d)]);
    std::array<bool, 3> refine{false, false, false};
    deviation = 0;
    for (int fixed = 0; fixed < 3; ++fixed) {
      const int a = (fixed + 1) % 3, b = (fixed + 2) % 3;
      for (double at : {dom.lo[fixed], dom.hi[fixed]}) {
        const double face =
            face_deviation(v, fixed, at, a, t[static_cast<std::size_t>(a)], b, t[static_cast<std::size_t>(b)], stop);
        // NaN (a face whose points overflow) counts as too coarse.
        if (!(face <= tolerance_mm)) refine[static_cast<std::size_t>(a)] = refine[static_cast<std::size_t>(b)] = true;
        deviation = std::isnan(face) ? HUGE_VAL : std::max(deviation, face);
      }
    }
    std::array<int, 3> next = n;
    for (int d = 0; d < 3; ++d)
      if (refine[static_cast<std::size_t>(d)] && next[static_cast<std::size_t>(d)] < kMaxSamples)
        next[static_cast<std::size_t>(d)] = std::min(kMaxSamples, 2 * next[static_cast<std::size_t>(d)] - 1);
    if (next == n || boundary_mesh_vertices(next) > max_vertices) break;
    n = next;
  }

  // Vertices are numbered in the order the triangles first reach them, and shared edges and
  // corners reuse them: a vertex's number is kept in the first face (in the loop's order) that
  // holds it, in a dense table of that face's grid.
  std::array<std::vector<double>, 3> t;
  for (int d = 0; d < 3; ++d)
    t[static_cast<std::size_t>(d)] = samples_of(dom.lo[d], dom.hi[d], n[static_cast<std::size_t>(d)]);
  struct FaceTable {
    int fixed, side, a, b;
    std::vector<int> id;  // per grid point of the face, index i_a + n_a * i_b; -1 = none yet
  };
  std::vector<FaceTable> faces;
  for (int fixed = 0; fixed < 3; ++fixed) {
    const int a = (fixed + 1) % 3, b = (fixed + 2) % 3;
    for (int side : {0, n[static_cast<std::size_t>(fixed)] - 1})
      faces.push_back({fixed, side, a, b,
                       std::vector<int>(static_cast<std::size_t>(n[static_cast<std::size_t>(a)]) *
                                            static_cast<std::size_t>(n[static_cast<std::size_t>(b)]),
                                        -1)});
  }
  std::vector<std::array<int, 3>> grid_of;  // per vertex: its grid index (i, j, k)
  std::vector<SlicedMesh::Triangle> triangles;
  auto vertex = [&](const std::array<int, 3>& ijk) {
    for (FaceTable& f : faces) {
      if (ijk[static_cast<std::size_t>(f.fixed)] != f.side) continue;
      int& id = f.id[static_cast<std::size_t>(ijk[static_cast<std::size_t>(f.a)]) +
                     static_cast<std::size_t>(n[static_cast<std::size_t>(f.a)]) *
                         static_cast<std::size_t>(ijk[static_cast<std::size_t>(f.b)])];
      if (id < 0) {
        id = static_cast<int>(grid_of.size());
        grid_of.push_back(ijk);
      }
      return id;
    }
    return -1;  // not on the boundary: never asked for
  };
  for (std::size_t face = 0; face < faces.size(); ++face) {
    const int fixed = faces[face].fixed, side = faces[face].side, a = faces[face].a, b = faces[face].b;
    for (int j = 1; j < n[static_cast<std::size_t>(b)]; ++j)
      for (int i = 1; i < n[static_cast<std::size_t>(a)]; ++i) {
        auto at = [&](int ii, int jj) {
          std::array<int, 3> ijk{};
          ijk[static_cast<std::size_t>(fixed)] = side;
          ijk[static_cast<std::size_t>(a)] = ii;
          ijk[static_cast<std::size_t>(b)] = jj;
          return vertex(ijk);
        };
        const int q00 = at(i - 1, j - 1), q10 = at(i, j - 1), q01 = at(i - 1, j), q11 = at(i, j);
        triangles.push_back({q00, q10, q11});
        triangles.push_back({q00, q11, q01});
      }
  }
  faces.clear();
  faces.shrink_to_fit();
  // Evaluated once numbered, together (evaluate_many gives each the value evaluate would).
  std::vector<Vec3> params(grid_of.size());
  for (std::size_t k = 0; k < grid_of.size(); ++k) {
    const auto& ijk = grid_of[k];
    params[k] = {t[0][static_cast<std::size_t>(ijk[0])], t[1][static_cast<std::size_t>(ijk[1])],
                 t[2][static_cast<std::size_t>(ijk[2])]};
  }
  std::vector<Vec3> vertices(grid_of.size());
  constexpr std::size_t kChunk = 1 << 16;  // vertices evaluated between reads of the stop flag
  for (std::size_t first = 0; first < params.size(); first += kChunk) {
    throw_if_stopped(stop);
    const std::size_t count = std::min(kChunk, params.size() - first);
    v.evaluate_many(std::span(params).subspan(first, count), std::span(vertices).subspan(first, count));
  }
  return {SlicedMesh(std::move(vertices), std::move(triangles)), n, deviation};
}

}  // namespace trivox::detail
