// Coons volume from six compatible faces: the Boolean-sum formula applied to homogeneous
// control points, with the linear blends taken at the Greville abscissae (see coons.h).
#include "trivox/construct/coons.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "construct/construct_util.h"
#include "trivox/error.h"
#include "trivox/spline/respace.h"

namespace trivox {

const char* coons_face_name(int face) noexcept {
  static const char* const kNames[6] = {"u0", "u1", "v0", "v1", "w0", "w1"};
  return face >= 0 && face < 6 ? kNames[face] : "?";
}

namespace {

using H = std::array<double, 4>;  // homogeneous point (w x, w y, w z, w)

H hom(const TensorSpline& s, int i, int j) {
  const auto p = s.point(i, j);
  const double w = s.weight(i, j);
  return {w * p[0], w * p[1], w * p[2], w};
}

// Checks that faces a and b agree along an edge: a's control points a(ia(t), ja(t)) and
// b's b(ib(t), jb(t)) for t = 0..count-1.
template <class FA, class FB>
void check_edge(const std::array<TensorSpline, 6>& f, int a, int b, const char* edge, int count, FA at_a, FB at_b,
                double tol) {
  for (int t = 0; t < count; ++t) {
    const auto [ia, ja] = at_a(t);
    const auto [ib, jb] = at_b(t);
    const H pa = hom(f[static_cast<std::size_t>(a)], ia, ja), pb = hom(f[static_cast<std::size_t>(b)], ib, jb);
    const Vec3 ea{pa[0] / pa[3], pa[1] / pa[3], pa[2] / pa[3]}, eb{pb[0] / pb[3], pb[1] / pb[3], pb[2] / pb[3]};
    const double d = norm(ea - eb);
    const double dw = std::abs(pa[3] - pb[3]) / std::max(pa[3], pb[3]);
    if (d > tol || dw > 1e-9)
      throw ModelError(fmt::format(
          "faces {} and {} do not share their edge ({}): control point {} of the edge differs by {:.6g} mm{} "
          "(check each face's parameter order: u0/u1 run in (v, w), v0/v1 in (u, w), w0/w1 in (u, v))",
          coons_face_name(a), coons_face_name(b), edge, t, d, dw > 1e-9 ? " and in weight" : ""));
  }
}

}  // namespace

Constructed coons(const std::array<TensorSpline, 6>& faces, const CoonsParams& params) {
  std::array<TensorSpline, 6> f = faces;
  for (int i = 0; i < 6; ++i)
    f[static_cast<std::size_t>(i)] =
        detail::checked_surface(f[static_cast<std::size_t>(i)], fmt::format("Coons face {}", coons_face_name(i)));
  bool rational = false;
  for (const TensorSpline& s : f) rational = rational || s.is_rational();
  if (rational)
    for (TensorSpline& s : f)
      if (!s.is_rational())
        s = TensorSpline(s.all_knots(), 3, std::vector<double>(s.points().begin(), s.points().end()),
                         std::vector<double>(static_cast<std::size_t>(s.total_ctrl()), 1.0));
  auto F = [&f](int i) { return &f[static_cast<std::size_t>(i)]; };
  // The volume's u, v, w directions as they appear in the faces; at least linear, so that
  // the linear blends are in the space.
  detail::make_compatible({{F(kFaceV0), 0}, {F(kFaceV1), 0}, {F(kFaceW0), 0}, {F(kFaceW1), 0}}, 2);
  detail::make_compatible({{F(kFaceU0), 0}, {F(kFaceU1), 0}, {F(kFaceW0), 1}, {F(kFaceW1), 1}}, 2);
  detail::make_compatible({{F(kFaceU0), 1}, {F(kFaceU1), 1}, {F(kFaceV0), 1}, {F(kFaceV1), 1}}, 2);
  const KnotVector ku = F(kFaceW0)->knots(0), kv = F(kFaceW0)->knots(1), kw = F(kFaceU0)->knots(1);
  const int nu = ku.num_ctrl(), nv = kv.num_ctrl(), nw = kw.num_ctrl();

  Box3 box;
  for (const TensorSpline& s : f) box.expand(s.control_box());
  const double tol = params.edge_tolerance_relative * std::max(box.diagonal(), 1e-300);
  using IJ = std::pair<int, int>;
  // Edges along w: (u = a, v = b) shared by faces u_a and v_b.
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      check_edge(
          f, kFaceU0 + a, kFaceV0 + b, fmt::format("u={}, v={}", a, b).c_str(), nw,
          [&](int t) {
            return IJ{b ? nv - 1 : 0, t};
          },
          [&](int t) {
            return IJ{a ? nu - 1 : 0, t};
          },
          tol);
  // Edges along v: (u = a, w = c), faces u_a and w_c.
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c)
      check_edge(
          f, kFaceU0 + a, kFaceW0 + c, fmt::format("u={}, w={}", a, c).c_str(), nv,
          [&](int t) {
            return IJ{t, c ? nw - 1 : 0};
          },
          [&](int t) {
            return IJ{a ? nu - 1 : 0, t};
          },
          tol);
  // Edges along u: (v = b, w = c), faces v_b and w_c.
  for (int b = 0; b < 2; ++b)
    for (int c = 0; c < 2; ++c)
      check_edge(
          f, kFaceV0 + b, kFaceW0 + c, fmt::format("v={}, w={}", b, c).c_str(), nu,
          [&](int t) {
            return IJ{t, c ? nw - 1 : 0};
          },
          [&](int t) {
            return IJ{t, b ? nv - 1 : 0};
          },
          tol);

  const std::vector<double> xu = greville_abscissae(ku), xv = greville_abscissae(kv), xw = greville_abscissae(kw);
  const auto U = [&](int a, int j, int k) { return hom(*F(kFaceU0 + a), j, k); };
  const auto V = [&](int b, int i, int k) { return hom(*F(kFaceV0 + b), i, k); };
  const auto W = [&](int c, int i, int j) { return hom(*F(kFaceW0 + c), i, j); };
  std::vector<double> pts, wts;
  for (int k = 0; k < nw; ++k)
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const double bu[2] = {1 - xu[static_cast<std::size_t>(i)], xu[static_cast<std::size_t>(i)]};
        const double bv[2] = {1 - xv[static_cast<std::size_t>(j)], xv[static_cast<std::size_t>(j)]};
        const double bw[2] = {1 - xw[static_cast<std::size_t>(k)], xw[static_cast<std::size_t>(k)]};
        const int je[2] = {0, nv - 1}, ke[2] = {0, nw - 1};
        H sum{};
        auto acc = [&sum](double c, const H& h) {
          for (std::size_t e = 0; e < 4; ++e) sum[e] += c * h[e];
        };
        for (int a = 0; a < 2; ++a) {
          acc(bu[a], U(a, j, k));
          acc(bv[a], V(a, i, k));
          acc(bw[a], W(a, i, j));
        }
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b) {
            acc(-bu[a] * bv[b], U(a, je[b], k));  // edges along w
            acc(-bu[a] * bw[b], U(a, j, ke[b]));  // edges along v
            acc(-bv[a] * bw[b], V(a, i, ke[b]));  // edges along u
            for (int c = 0; c < 2; ++c) acc(bu[a] * bv[b] * bw[c], U(a, je[b], ke[c]));
          }
        if (!(sum[3] > 0.0))
          throw ModelError(
              fmt::format("the Coons blend of these rational faces has a non-positive weight {} at control "
                          "point ({}, {}, {}); give the faces compatible weights",
                          sum[3], i, j, k));
        pts.insert(pts.end(), {sum[0] / sum[3], sum[1] / sum[3], sum[2] / sum[3]});
        wts.push_back(sum[3]);
      }
  if (!rational) wts.clear();
  TensorSpline v({ku, kv, kw}, 3, std::move(pts), std::move(wts));
  return detail::finish("coons", std::move(v), params.check);
}

namespace {

// The corner of a clamped surface at (a, b) in {0, 1}^2.
Vec3 corner(const TensorSpline& s, int a, int b) {
  return detail::to_vec3(s.point(a ? s.num_ctrl(0) - 1 : 0, b ? s.num_ctrl(1) - 1 : 0));
}

}  // namespace

std::array<TensorSpline, 6> arrange_cube_faces(const std::vector<TensorSpline>& surfaces, double tolerance_relative) {
  if (surfaces.size() != 6)
    throw ModelError(fmt::format("a shell of cube topology has 6 faces, not {}", surfaces.size()));
  std::vector<TensorSpline> f;
  Box3 box;
  for (std::size_t i = 0; i < 6; ++i) {
    f.push_back(detail::checked_surface(surfaces[i], fmt::format("face {} of the shell", i)));
    box.expand(f.back().control_box());
  }
  const double tol = tolerance_relative * std::max(box.diagonal(), 1e-300);
  // Vertices: the corners, merged within the tolerance.
  std::vector<Vec3> vertices;
  const auto vertex_of = [&](Vec3 p) {
    for (std::size_t v = 0; v < vertices.size(); ++v)
      if (norm(vertices[v] - p) <= tol) return static_cast<int>(v);
    vertices.push_back(p);
    return static_cast<int>(vertices.size()) - 1;
  };
  std::vector<std::array<int, 4>> ids;  // per face: corners (0,0), (1,0), (0,1), (1,1)
  for (std::size_t i = 0; i < 6; ++i) {
    std::array<int, 4> c{};
    for (int q = 0; q < 4; ++q) c[static_cast<std::size_t>(q)] = vertex_of(corner(f[i], q & 1, q >> 1));
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (c[static_cast<std::size_t>(a)] == c[static_cast<std::size_t>(b)])
          throw ModelError(fmt::format("face {} of the shell has two corners at the same point: not a cube face", i));
    ids.push_back(c);
  }
  if (vertices.size() != 8)
    throw ModelError(
        fmt::format("the corners of the six faces make {} distinct points, not the 8 of a cube", vertices.size()));
  // Edges of the vertex graph, from the faces' sides.
  std::vector<std::array<bool, 8>> adjacent(8);
  for (const auto& c : ids)
    for (const auto& [a, b] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 3}, std::pair{2, 3}}) {
      adjacent[static_cast<std::size_t>(c[static_cast<std::size_t>(a)])]
              [static_cast<std::size_t>(c[static_cast<std::size_t>(b)])] = true;
      adjacent[static_cast<std::size_t>(c[static_cast<std::size_t>(b)])]
              [static_cast<std::size_t>(c[static_cast<std::size_t>(a)])] = true;
    }
  // Volume corner (i, j, k) -> vertex: face 0 is w = 0, each of its corners' one neighbour
  // off face 0 is the corner above it.
  std::array<int, 8> at{};  // index i + 2 j + 4 k
  for (int q = 0; q < 4; ++q) {
    const int v = ids[0][static_cast<std::size_t>(q)];
    at[static_cast<std::size_t>(q)] = v;
    int above = -1;
    for (int w = 0; w < 8; ++w)
      if (adjacent[static_cast<std::size_t>(v)][static_cast<std::size_t>(w)] &&
          std::find(ids[0].begin(), ids[0].end(), w) == ids[0].end()) {
        if (above >= 0)
          throw ModelError("the six faces do not meet like the faces of a cube (a corner has more than 3 edges)");
        above = w;
      }
    if (above < 0)
      throw ModelError(
          "the six faces do not meet like the faces of a cube (a corner of the first face has no edge off it)");
    at[static_cast<std::size_t>(q + 4)] = above;
  }
  std::array<TensorSpline, 6> out{f[0], f[0], f[0], f[0], f[0], f[0]};
  std::array<bool, 6> used{true, false, false, false, false, false};
  for (int face = 0; face < 6; ++face) {
    const int d = face / 2, side = face % 2;
    const int a = d == 0 ? 1 : 0, b = d == 2 ? 1 : 2;
    std::array<int, 4> want{};
    for (int q = 0; q < 4; ++q) {
      std::array<int, 3> ijk{};
      ijk[static_cast<std::size_t>(d)] = side;
      ijk[static_cast<std::size_t>(a)] = q & 1;
      ijk[static_cast<std::size_t>(b)] = q >> 1;
      want[static_cast<std::size_t>(q)] = at[static_cast<std::size_t>(ijk[0] + 2 * ijk[1] + 4 * ijk[2])];
    }
    bool found = false;
    for (std::size_t i = 0; i < 6 && !found; ++i) {
      if (face != kFaceW0 && used[i]) continue;
      if (face == kFaceW0 && i != 0) continue;
      // The 8 ways to lay a square's parameters on it: swap, then reverse either direction.
      for (int t = 0; t < 8 && !found; ++t) {
        const bool swap = t & 4, rev0 = t & 1, rev1 = t & 2;
        std::array<int, 4> got{};
        for (int q = 0; q < 4; ++q) {
          int s0 = q & 1, s1 = q >> 1;  // the arranged face's corner (s0, s1)
          if (rev0) s0 = 1 - s0;
          if (rev1) s1 = 1 - s1;
          const int p0 = swap ? s1 : s0, p1 = swap ? s0 : s1;  // the input face's corner
          got[static_cast<std::size_t>(q)] = ids[i][static_cast<std::size_t>(p0 + 2 * p1)];
        }
        if (got != want) continue;
        TensorSpline s = f[i];
        if (swap) {
          const std::array<int, 2> order{1, 0};
          s = permuted(s, order);
        }
        if (rev0) s = reversed(s, 0);
        if (rev1) s = reversed(s, 1);
        out[static_cast<std::size_t>(face)] = std::move(s);
        used[i] = true;
        found = true;
      }
    }
    if (!found)
      throw ModelError(
          fmt::format("no face of the shell has the corners of the Coons face {}: the faces do not meet like "
                      "the faces of a cube",
                      coons_face_name(face)));
  }
  return out;
}

}  // namespace trivox
