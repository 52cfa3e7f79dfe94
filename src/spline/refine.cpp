// Knot insertion (The NURBS Book, A5.1) applied along one direction of a tensor grid of
// homogeneous control points, and the operations built from it: clamping, splitting,
// restriction to a sub-box, Bezier extraction.
#include "trivox/spline/refine.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

namespace {

// Control points in basis-index layout (periodic directions unwrapped), homogeneous
// (w*x..., w) for rational splines, plain Euclidean otherwise so that polynomial weights
// stay exactly 1.
struct Grid {
  std::vector<std::vector<double>> knots;  // one knot vector per direction (never periodic)
  std::vector<int> order;
  std::array<int, 3> n{1, 1, 1};  // control points per direction
  int dim = 3;                    // Euclidean point dimension
  bool rational = false;
  std::vector<double> data;  // n[0]*n[1]*n[2] rows of hdim() values, u fastest

  int hdim() const { return rational ? dim + 1 : dim; }
  std::size_t offset(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) +
            static_cast<std::size_t>(n[0]) *
                (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(k))) *
           static_cast<std::size_t>(hdim());
  }
  double* at(int i, int j, int k) { return &data[offset(i, j, k)]; }
  const double* at(int i, int j, int k) const { return &data[offset(i, j, k)]; }
};

Grid to_grid(const TensorSpline& s) {
  Grid g;
  g.dim = s.point_dim();
  g.rational = s.is_rational();
  for (int d = 0; d < s.param_dim(); ++d) {
    const KnotVector& kv = s.knots(d);
    g.knots.emplace_back(kv.knots().begin(), kv.knots().end());
    g.order.push_back(kv.order());
    g.n[static_cast<std::size_t>(d)] = kv.num_basis();
  }
  g.data.resize(static_cast<std::size_t>(g.n[0] * g.n[1] * g.n[2] * g.hdim()));
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) {
        const int ci = s.knots(0).ctrl_index(i);
        const int cj = s.param_dim() > 1 ? s.knots(1).ctrl_index(j) : 0;
        const int ck = s.param_dim() > 2 ? s.knots(2).ctrl_index(k) : 0;
        const auto p = s.point(ci, cj, ck);
        const double w = s.weight(ci, cj, ck);
        double* out = g.at(i, j, k);
        for (int c = 0; c < g.dim; ++c)
          out[c] = g.rational ? w * p[static_cast<std::size_t>(c)] : p[static_cast<std::size_t>(c)];
        if (g.rational) out[g.dim] = w;
      }
  return g;
}

TensorSpline from_grid(const Grid& g) {
  std::vector<KnotVector> kvs;
  for (std::size_t d = 0; d < g.knots.size(); ++d) kvs.emplace_back(g.order[d], g.knots[d]);
  const std::size_t count = static_cast<std::size_t>(g.n[0] * g.n[1] * g.n[2]);
  std::vector<double> pts(count * static_cast<std::size_t>(g.dim));
  std::vector<double> w;
  if (g.rational) w.resize(count);
  const auto hd = static_cast<std::size_t>(g.hdim());
  for (std::size_t p = 0; p < count; ++p) {
    const double* h = &g.data[p * hd];
    const double wt = g.rational ? h[g.dim] : 1.0;
    for (std::size_t c = 0; c < static_cast<std::size_t>(g.dim); ++c)
      pts[p * static_cast<std::size_t>(g.dim) + c] = g.rational ? h[c] / wt : h[c];
    if (g.rational) w[p] = wt;
  }
  return TensorSpline(std::move(kvs), g.dim, std::move(pts), std::move(w));
}

// Inserts u `r` times into direction d of the grid (A5.1 applied to every line along d).
void insert(Grid& g, int d, double u, int r) {
  if (r <= 0) return;
  auto& U = g.knots[static_cast<std::size_t>(d)];
  const int p = g.order[static_cast<std::size_t>(d)] - 1;
  const int np = g.n[static_cast<std::size_t>(d)];
  // Span k with U[k] <= u < U[k+1], taking the last of equal knots.
  const int k = static_cast<int>(std::upper_bound(U.begin(), U.end(), u) - U.begin()) - 1;
  const int m = static_cast<int>(std::count(U.begin(), U.end(), u));
  if (k < p || k > np || m + r > p + 1)
    throw ModelError(
        fmt::format("cannot insert knot {} {} time(s): outside the domain or multiplicity above the order", u, r));
  // A5.1 raises a multiplicity up to the degree p. Reaching the order p + 1 (a break, used
  // for splitting) then only duplicates the control point C(u) = P[k - p]: the copy loops
  // below do exactly that when the blending loop is skipped.
  if (m < p && m + r > p) {
    insert(g, d, u, p - m);
    insert(g, d, u, m + r - p);
    return;
  }
  const bool duplicate_only = (m == p);
  std::vector<double> UQ;
  UQ.reserve(U.size() + static_cast<std::size_t>(r));
  UQ.insert(UQ.end(), U.begin(), U.begin() + k + 1);
  UQ.insert(UQ.end(), static_cast<std::size_t>(r), u);
  UQ.insert(UQ.end(), U.begin() + k + 1, U.end());

  Grid out = g;
  out.n[static_cast<std::size_t>(d)] = np + r;
  out.data.assign(static_cast<std::size_t>(out.n[0] * out.n[1] * out.n[2] * out.hdim()), 0.0);
  const int hd = g.hdim();
  std::array<int, 3> other{};
  int a = (d == 0) ? 1 : 0, b = (d == 2) ? 1 : 2;
  std::vector<double> R(static_cast<std::size_t>((p + 1) * hd));
  auto idx = [&](std::array<int, 3>& ijk, int dir_index, int value) {
    ijk[static_cast<std::size_t>(dir_index)] = value;
    return ijk;
  };
  for (int s = 0; s < g.n[static_cast<std::size_t>(b)]; ++s)
    for (int t = 0; t < g.n[static_cast<std::size_t>(a)]; ++t) {
      other[static_cast<std::size_t>(a)] = t;
      other[static_cast<std::size_t>(b)] = s;
      auto P = [&](int i) {
        auto ijk = idx(other, d, i);
        return g.at(ijk[0], ijk[1], ijk[2]);
      };
      auto Q = [&](int i) {
        auto ijk = idx(other, d, i);
        return out.at(ijk[0], ijk[1], ijk[2]);
      };
      auto copy = [&](double* dst, const double* src) { std::copy(src, src + hd, dst); };
      for (int i = 0; i <= k - p; ++i) copy(Q(i), P(i));
      for (int i = k - m; i < np; ++i) copy(Q(i + r), P(i));
      for (int i = 0; i <= p - m; ++i) std::copy(P(k - p + i), P(k - p + i) + hd, &R[static_cast<std::size_t>(i * hd)]);
      int L = k - p;
      if (duplicate_only) continue;
      for (int j = 1; j <= r; ++j) {
        L = k - p + j;
        for (int i = 0; i <= p - j - m; ++i) {
          const double alpha = (u - U[static_cast<std::size_t>(L + i)]) /
                               (U[static_cast<std::size_t>(i + k + 1)] - U[static_cast<std::size_t>(L + i)]);
          for (int c = 0; c < hd; ++c) {
            double& ri = R[static_cast<std::size_t>(i * hd + c)];
            ri = alpha * R[static_cast<std::size_t>((i + 1) * hd + c)] + (1.0 - alpha) * ri;
          }
        }
        copy(Q(L), &R[0]);
        copy(Q(k + r - j - m), &R[static_cast<std::size_t>((p - j - m) * hd)]);
      }
      for (int i = L + 1; i < k - m; ++i) copy(Q(i), &R[static_cast<std::size_t>((i - L) * hd)]);
    }
  out.knots[static_cast<std::size_t>(d)] = std::move(UQ);
  g = std::move(out);
}

// Keeps control points [first[d], first[d] + count[d]) and knots [first[d], first[d] +
// count[d] + order) along every direction d, copying nothing else of the grid.
Grid block(const Grid& g, const std::array<int, 3>& first, const std::array<int, 3>& count) {
  Grid out;
  out.order = g.order;
  out.dim = g.dim;
  out.rational = g.rational;
  out.n = count;
  for (std::size_t d = 0; d < g.knots.size(); ++d) {
    const auto& U = g.knots[d];
    out.knots.emplace_back(U.begin() + first[d], U.begin() + first[d] + count[d] + g.order[d]);
  }
  out.data.resize(static_cast<std::size_t>(out.n[0] * out.n[1] * out.n[2] * out.hdim()));
  const int hd = g.hdim();
  for (int k = 0; k < out.n[2]; ++k)
    for (int j = 0; j < out.n[1]; ++j)
      for (int i = 0; i < out.n[0]; ++i) {
        const double* p = g.at(i + first[0], j + first[1], k + first[2]);
        std::copy(p, p + hd, out.at(i, j, k));
      }
  return out;
}

// Keeps control points [first, first+count) and knots [first, first+count+order) along d.
void crop(Grid& g, int d, int first, int count) {
  std::array<int, 3> firsts{0, 0, 0};
  std::array<int, 3> counts = g.n;
  firsts[static_cast<std::size_t>(d)] = first;
  counts[static_cast<std::size_t>(d)] = count;
  g = block(g, firsts, counts);
}

void raise_multiplicity(Grid& g, int d, double t, int target) {
  const auto& U = g.knots[static_cast<std::size_t>(d)];
  const int m = static_cast<int>(std::count(U.begin(), U.end(), t));
  if (m < target) insert(g, d, t, target - m);
}

// Clamps both ends of direction d and drops what lies outside the domain.
void clamp_direction(Grid& g, int d) {
  const int k = g.order[static_cast<std::size_t>(d)];
  const double lo = g.knots[static_cast<std::size_t>(d)][static_cast<std::size_t>(k - 1)];
  const double hi = g.knots[static_cast<std::size_t>(d)][static_cast<std::size_t>(g.n[static_cast<std::size_t>(d)])];
  raise_multiplicity(g, d, lo, k);
  raise_multiplicity(g, d, hi, k);
  const auto& U = g.knots[static_cast<std::size_t>(d)];
  const int first = static_cast<int>(std::lower_bound(U.begin(), U.end(), lo) - U.begin());
  const int last_hi = static_cast<int>(std::upper_bound(U.begin(), U.end(), hi) - U.begin()) - 1;
  // Knots kept: [first, last_hi], count = last_hi - first + 1 = ctrl + order.
  crop(g, d, first, last_hi - first + 1 - k);
}

}  // namespace

TensorSpline insert_knot(const TensorSpline& s, int dir, double t, int times) {
  if (dir < 0 || dir >= s.param_dim()) throw ModelError(fmt::format("no parametric direction {}", dir));
  if (!(t >= s.lo(dir) && t <= s.hi(dir)))
    throw ModelError(fmt::format("knot {} lies outside the domain [{}, {}]", t, s.lo(dir), s.hi(dir)));
  Grid g = to_grid(s);
  insert(g, dir, t, times);
  return from_grid(g);
}

TensorSpline clamped(const TensorSpline& s) {
  bool already = true;
  for (int d = 0; d < s.param_dim(); ++d) already = already && s.knots(d).is_clamped();
  if (already) return s;
  Grid g = to_grid(s);
  for (int d = 0; d < s.param_dim(); ++d) clamp_direction(g, d);
  return from_grid(g);
}

std::pair<TensorSpline, TensorSpline> split(const TensorSpline& s, int dir, double t) {
  if (dir < 0 || dir >= s.param_dim()) throw ModelError(fmt::format("no parametric direction {}", dir));
  if (!(t > s.lo(dir) && t < s.hi(dir)))
    throw ModelError(fmt::format("split parameter {} is not inside the domain ({}, {})", t, s.lo(dir), s.hi(dir)));
  Grid g = to_grid(clamped(s));
  const int k = g.order[static_cast<std::size_t>(dir)];
  raise_multiplicity(g, dir, t, k);
  const auto& U = g.knots[static_cast<std::size_t>(dir)];
  const int a = static_cast<int>(std::lower_bound(U.begin(), U.end(), t) - U.begin());
  Grid left = g, right = g;
  crop(left, dir, 0, a);
  crop(right, dir, a, g.n[static_cast<std::size_t>(dir)] - a);
  return {from_grid(left), from_grid(right)};
}

TensorSpline restrict_to(const TensorSpline& s, std::span<const double> lo, std::span<const double> hi) {
  TensorSpline out = clamped(s);
  for (int d = 0; d < s.param_dim(); ++d) {
    const double a = std::max(lo[static_cast<std::size_t>(d)], s.lo(d));
    const double b = std::min(hi[static_cast<std::size_t>(d)], s.hi(d));
    if (!(a < b)) throw ModelError(fmt::format("empty sub-box [{}, {}] along direction {}", a, b, d));
    if (a > out.lo(d)) out = split(out, d, a).second;
    if (b < out.hi(d)) out = split(out, d, b).first;
  }
  return out;
}

std::vector<TensorSpline> bezier_patches(const TensorSpline& s) {
  Grid g = to_grid(clamped(s));
  std::array<int, 3> pieces{1, 1, 1};
  for (int d = 0; d < s.param_dim(); ++d) {
    const int k = g.order[static_cast<std::size_t>(d)];
    const std::vector<double> breaks = s.knots(d).interior_breaks();
    for (double t : breaks) raise_multiplicity(g, d, t, k);
    pieces[static_cast<std::size_t>(d)] = static_cast<int>(breaks.size()) + 1;
  }
  std::vector<TensorSpline> out;
  out.reserve(static_cast<std::size_t>(pieces[0] * pieces[1] * pieces[2]));
  for (int pk = 0; pk < pieces[2]; ++pk)
    for (int pj = 0; pj < pieces[1]; ++pj)
      for (int pi = 0; pi < pieces[0]; ++pi) {
        const std::array<int, 3> index{pi, pj, pk};
        std::array<int, 3> first{0, 0, 0};
        std::array<int, 3> count = g.n;
        for (int d = 0; d < s.param_dim(); ++d) {
          const int k = g.order[static_cast<std::size_t>(d)];
          first[static_cast<std::size_t>(d)] = index[static_cast<std::size_t>(d)] * k;
          count[static_cast<std::size_t>(d)] = k;
        }
        out.push_back(from_grid(block(g, first, count)));
      }
  return out;
}

}  // namespace trivox
