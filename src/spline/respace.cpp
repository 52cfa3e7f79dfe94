// Exact changes of spline space by interpolation at Greville abscissae (see respace.h), and
// the reparametrizations that only relabel knots or control points.
#include "trivox/spline/respace.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/spline/detail/basis.h"
#include "trivox/spline/refine.h"

namespace trivox {

namespace {

// Row-major dense matrix of basis values: row r holds N_0..N_{n-1} at params[r].
std::vector<double> collocation(const KnotVector& kv, std::span<const double> params) {
  const auto n = static_cast<std::size_t>(kv.num_basis());
  const int k = kv.order();
  std::vector<double> m(params.size() * n, 0.0);
  std::array<double, kMaxOrder> N{};
  for (std::size_t r = 0; r < params.size(); ++r) {
    const int span = kv.find_span(params[r]);
    basis_functions(kv, span, params[r], N.data());
    for (int j = 0; j < k; ++j) m[r * n + static_cast<std::size_t>(span - k + 1 + j)] = N[static_cast<std::size_t>(j)];
  }
  return m;
}

// Solves A X = B in place (A: n x n, B: n x cols, both row-major) by Gaussian elimination
// with partial pivoting. Returns false when A is numerically singular.
bool solve_dense(std::vector<double>& A, std::vector<double>& B, std::size_t n, std::size_t cols) {
  double scale = 0;
  for (double a : A) scale = std::max(scale, std::abs(a));
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t piv = c;
    for (std::size_t r = c + 1; r < n; ++r)
      if (std::abs(A[r * n + c]) > std::abs(A[piv * n + c])) piv = r;
    if (!(std::abs(A[piv * n + c]) > 1e-13 * scale)) return false;
    if (piv != c) {
      for (std::size_t j = 0; j < n; ++j) std::swap(A[c * n + j], A[piv * n + j]);
      for (std::size_t j = 0; j < cols; ++j) std::swap(B[c * cols + j], B[piv * cols + j]);
    }
    const double inv = 1.0 / A[c * n + c];
    for (std::size_t r = c + 1; r < n; ++r) {
      const double f = A[r * n + c] * inv;
      if (f == 0.0) continue;
      for (std::size_t j = c; j < n; ++j) A[r * n + j] -= f * A[c * n + j];
      for (std::size_t j = 0; j < cols; ++j) B[r * cols + j] -= f * B[c * cols + j];
    }
  }
  for (std::size_t c = n; c-- > 0;) {
    for (std::size_t j = 0; j < cols; ++j) {
      double v = B[c * cols + j];
      for (std::size_t r = c + 1; r < n; ++r) v -= A[c * n + r] * B[r * cols + j];
      B[c * cols + j] = v / A[c * n + c];
    }
  }
  return true;
}

// Homogeneous control data of a clamped spline: total_ctrl rows of (w*x..., w), or plain
// Euclidean rows for a polynomial spline.
struct Homogeneous {
  std::vector<KnotVector> knots;
  int dim = 3;
  bool rational = false;
  std::array<int, 3> n{1, 1, 1};
  std::vector<double> data;
  std::size_t hdim() const { return static_cast<std::size_t>(rational ? dim + 1 : dim); }
};

Homogeneous to_homogeneous(const TensorSpline& s) {
  Homogeneous h;
  h.knots = s.all_knots();
  h.dim = s.point_dim();
  h.rational = s.is_rational();
  for (int d = 0; d < 3; ++d) h.n[static_cast<std::size_t>(d)] = s.num_ctrl(d);
  const std::size_t hd = h.hdim();
  h.data.resize(static_cast<std::size_t>(s.total_ctrl()) * hd);
  for (int p = 0; p < s.total_ctrl(); ++p) {
    const auto pt = s.points().subspan(static_cast<std::size_t>(p * h.dim), static_cast<std::size_t>(h.dim));
    const double w = h.rational ? s.weights()[static_cast<std::size_t>(p)] : 1.0;
    for (std::size_t c = 0; c < static_cast<std::size_t>(h.dim); ++c)
      h.data[static_cast<std::size_t>(p) * hd + c] = w * pt[c];
    if (h.rational) h.data[static_cast<std::size_t>(p) * hd + static_cast<std::size_t>(h.dim)] = w;
  }
  return h;
}

TensorSpline from_homogeneous(Homogeneous h) {
  const std::size_t count =
      static_cast<std::size_t>(h.n[0]) * static_cast<std::size_t>(h.n[1]) * static_cast<std::size_t>(h.n[2]);
  const std::size_t hd = h.hdim(), dim = static_cast<std::size_t>(h.dim);
  std::vector<double> pts(count * dim), w;
  if (h.rational) w.resize(count);
  for (std::size_t p = 0; p < count; ++p) {
    const double wt = h.rational ? h.data[p * hd + dim] : 1.0;
    for (std::size_t c = 0; c < dim; ++c) pts[p * dim + c] = h.data[p * hd + c] / wt;
    if (h.rational) w[p] = wt;
  }
  return TensorSpline(std::move(h.knots), h.dim, std::move(pts), std::move(w));
}

// Applies the n_new x n_old matrix M to every line of control data along `dir`.
void apply_along(Homogeneous& h, int dir, const std::vector<double>& M, int n_new) {
  const auto d = static_cast<std::size_t>(dir);
  const std::size_t hd = h.hdim();
  std::array<int, 3> n_out = h.n;
  n_out[d] = n_new;
  const int n_old = h.n[d];
  std::vector<double> out(
      static_cast<std::size_t>(n_out[0]) * static_cast<std::size_t>(n_out[1]) * static_cast<std::size_t>(n_out[2]) * hd,
      0.0);
  auto lin = [](const std::array<int, 3>& n, std::array<int, 3> ijk) {
    return static_cast<std::size_t>(ijk[0] + n[0] * (ijk[1] + n[1] * ijk[2]));
  };
  std::array<int, 3> ijk{};
  for (ijk[2] = 0; ijk[2] < n_out[2]; ++ijk[2])
    for (ijk[1] = 0; ijk[1] < n_out[1]; ++ijk[1])
      for (ijk[0] = 0; ijk[0] < n_out[0]; ++ijk[0]) {
        const int r = ijk[d];
        double* dst = &out[lin(n_out, ijk) * hd];
        std::array<int, 3> src = ijk;
        for (int c = 0; c < n_old; ++c) {
          const double m =
              M[static_cast<std::size_t>(r) * static_cast<std::size_t>(n_old) + static_cast<std::size_t>(c)];
          if (m == 0.0) continue;
          src[d] = c;
          const double* s = &h.data[lin(h.n, src) * hd];
          for (std::size_t e = 0; e < hd; ++e) dst[e] += m * s[e];
        }
      }
  h.n = n_out;
  h.data = std::move(out);
}

void check_dir(const TensorSpline& s, int dir) {
  if (dir < 0 || dir >= s.param_dim())
    throw ModelError(fmt::format("no parametric direction {} in a spline of {} parameter(s)", dir, s.param_dim()));
}

}  // namespace

std::vector<double> greville_abscissae(const KnotVector& kv) {
  const int n = kv.num_basis(), p = kv.degree();
  std::vector<double> g(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    if (p == 0) {
      g[static_cast<std::size_t>(i)] = 0.5 * (kv[i] + kv[i + 1]);
      continue;
    }
    double s = 0;
    for (int j = 1; j <= p; ++j) s += kv[i + j];
    g[static_cast<std::size_t>(i)] = std::clamp(s / p, kv.lo(), kv.hi());
  }
  return g;
}

std::vector<double> interpolate_values(const KnotVector& kv, std::span<const double> params,
                                       std::span<const double> values, int dim) {
  const auto n = static_cast<std::size_t>(kv.num_basis());
  const auto cols = static_cast<std::size_t>(dim);
  if (params.size() != n || values.size() != n * cols)
    throw ModelError(fmt::format("interpolation needs {} parameters and {} values, got {} and {}", n, n * cols,
                                 params.size(), values.size()));
  std::vector<double> A = collocation(kv, params);
  std::vector<double> B(values.begin(), values.end());
  if (!solve_dense(A, B, n, cols))
    throw ModelError("the interpolation parameters do not suit the knot vector (singular collocation matrix)");
  return B;
}

KnotVector elevated_knots(const KnotVector& kv, int times) {
  std::vector<double> out;
  const std::vector<double> breaks = kv.interior_breaks();
  const int order = kv.order() + times;
  out.insert(out.end(), static_cast<std::size_t>(order), kv.lo());
  for (double b : breaks) out.insert(out.end(), static_cast<std::size_t>(kv.multiplicity(b) + times), b);
  out.insert(out.end(), static_cast<std::size_t>(order), kv.hi());
  return KnotVector(order, std::move(out));
}

TensorSpline respace(const TensorSpline& s, int dir, const KnotVector& target) {
  check_dir(s, dir);
  const TensorSpline c = clamped(s);
  const KnotVector& kv = c.knots(dir);
  if (target.is_periodic() || !target.is_clamped())
    throw ModelError("the target knot vector must be clamped and not periodic");
  if (target.lo() != kv.lo() || target.hi() != kv.hi())
    throw ModelError(fmt::format("the target domain [{}, {}] differs from the spline's [{}, {}]", target.lo(),
                                 target.hi(), kv.lo(), kv.hi()));
  const int raise = target.order() - kv.order();
  if (raise < 0)
    throw ModelError(fmt::format("the target order {} is below the spline's order {}", target.order(), kv.order()));
  for (double b : kv.interior_breaks())
    if (target.multiplicity(b) < kv.multiplicity(b) + raise)
      throw ModelError(fmt::format("the target space lacks the knot {} (multiplicity {} needed, {} present)", b,
                                   kv.multiplicity(b) + raise, target.multiplicity(b)));
  if (target == kv) return c;
  const std::vector<double> xi = greville_abscissae(target);
  // M = B_target^{-1} A_old: the new control values as combinations of the old ones.
  std::vector<double> A = collocation(target, xi);
  std::vector<double> M = collocation(kv, xi);
  const auto n_new = static_cast<std::size_t>(target.num_basis());
  if (!solve_dense(A, M, n_new, static_cast<std::size_t>(kv.num_basis())))
    throw ModelError("singular collocation matrix at the target's Greville abscissae");
  Homogeneous h = to_homogeneous(c);
  apply_along(h, dir, M, target.num_basis());
  h.knots[static_cast<std::size_t>(dir)] = target;
  return from_homogeneous(std::move(h));
}

TensorSpline elevate_degree(const TensorSpline& s, int dir, int times) {
  check_dir(s, dir);
  if (times < 0) throw ModelError(fmt::format("cannot elevate the degree by {} (< 0)", times));
  const TensorSpline c = clamped(s);
  if (times == 0) return c;
  if (c.knots(dir).order() + times > kMaxOrder)
    throw ModelError(
        fmt::format("elevating order {} by {} exceeds the maximum order {}", c.knots(dir).order(), times, kMaxOrder));
  return respace(c, dir, elevated_knots(c.knots(dir), times));
}

TensorSpline reparametrized(const TensorSpline& s, int dir, double lo, double hi) {
  check_dir(s, dir);
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi))
    throw ModelError(fmt::format("the domain [{}, {}] is empty or not finite", lo, hi));
  const KnotVector& kv = s.knots(dir);
  const double a = kv.lo(), b = kv.hi();
  std::vector<double> t(kv.knots().begin(), kv.knots().end());
  for (double& x : t) x = (x == a) ? lo : (x == b) ? hi : lo + (x - a) * (hi - lo) / (b - a);
  // Keep the knots non-decreasing even where rounding would nudge one past a neighbour.
  for (std::size_t i = 1; i < t.size(); ++i) t[i] = std::max(t[i], t[i - 1]);
  std::vector<KnotVector> knots = s.all_knots();
  knots[static_cast<std::size_t>(dir)] = kv.is_periodic()
                                             ? KnotVector::periodic(kv.order(), kv.num_ctrl(), std::move(t))
                                             : KnotVector(kv.order(), std::move(t));
  return TensorSpline(std::move(knots), s.point_dim(), std::vector<double>(s.points().begin(), s.points().end()),
                      std::vector<double>(s.weights().begin(), s.weights().end()));
}

TensorSpline permuted(const TensorSpline& s, std::span<const int> order) {
  const int pd = s.param_dim();
  if (static_cast<int>(order.size()) != pd) throw ModelError("the permutation has the wrong length");
  std::array<bool, 3> seen{};
  for (int o : order) {
    if (o < 0 || o >= pd || seen[static_cast<std::size_t>(o)]) throw ModelError("not a permutation of the directions");
    seen[static_cast<std::size_t>(o)] = true;
  }
  std::vector<KnotVector> knots;
  for (int o : order) knots.push_back(s.knots(o));
  std::array<int, 3> n{1, 1, 1};
  for (int d = 0; d < pd; ++d) n[static_cast<std::size_t>(d)] = s.num_ctrl(order[static_cast<std::size_t>(d)]);
  const auto dim = static_cast<std::size_t>(s.point_dim());
  std::vector<double> pts(s.points().size()), w(s.weights().size());
  std::array<int, 3> out{}, src{};
  std::size_t p = 0;
  for (out[2] = 0; out[2] < n[2]; ++out[2])
    for (out[1] = 0; out[1] < n[1]; ++out[1])
      for (out[0] = 0; out[0] < n[0]; ++out[0], ++p) {
        src = {0, 0, 0};
        for (int d = 0; d < pd; ++d)
          src[static_cast<std::size_t>(order[static_cast<std::size_t>(d)])] = out[static_cast<std::size_t>(d)];
        const auto q = s.point(src[0], src[1], src[2]);
        std::copy(q.begin(), q.end(), pts.begin() + static_cast<std::ptrdiff_t>(p * dim));
        if (!w.empty()) w[p] = s.weight(src[0], src[1], src[2]);
      }
  return TensorSpline(std::move(knots), s.point_dim(), std::move(pts), std::move(w));
}

TensorSpline reversed(const TensorSpline& in, int dir) {
  check_dir(in, dir);
  // A periodic direction's wrapped control indices do not simply reverse: unwrap it first.
  if (in.knots(dir).is_periodic()) return reversed(clamped(in), dir);
  const TensorSpline& s = in;
  const KnotVector& kv = s.knots(dir);
  const double a = kv.lo(), b = kv.hi();
  std::vector<double> t(kv.knots().rbegin(), kv.knots().rend());
  for (double& x : t) x = a + b - x;
  std::vector<KnotVector> knots = s.all_knots();
  knots[static_cast<std::size_t>(dir)] = KnotVector(kv.order(), std::move(t));
  const auto dim = static_cast<std::size_t>(s.point_dim());
  std::vector<double> pts(s.points().size()), w(s.weights().size());
  std::array<int, 3> ijk{}, src{};
  const int nd = s.num_ctrl(dir);
  std::size_t p = 0;
  for (ijk[2] = 0; ijk[2] < s.num_ctrl(2); ++ijk[2])
    for (ijk[1] = 0; ijk[1] < s.num_ctrl(1); ++ijk[1])
      for (ijk[0] = 0; ijk[0] < s.num_ctrl(0); ++ijk[0], ++p) {
        src = ijk;
        src[static_cast<std::size_t>(dir)] = nd - 1 - ijk[static_cast<std::size_t>(dir)];
        const auto q = s.point(src[0], src[1], src[2]);
        std::copy(q.begin(), q.end(), pts.begin() + static_cast<std::ptrdiff_t>(p * dim));
        if (!w.empty()) w[p] = s.weight(src[0], src[1], src[2]);
      }
  return TensorSpline(std::move(knots), s.point_dim(), std::move(pts), std::move(w));
}

}  // namespace trivox
