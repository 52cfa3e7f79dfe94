#include "trimmed_tessellation.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::detail {

namespace {

// A trimming curve as a polyline in (u, v): its control points when it is piecewise linear
// (order 2, IRIT's usual trimming curves), else 8 samples per knot span.
std::vector<Vec3> curve_polyline(const TensorSpline& c) {
  std::vector<Vec3> out;
  const int order = c.knots(0).order();
  const int spans = static_cast<int>(c.knots(0).interior_breaks().size()) + 1;
  const int m = order == 2 ? spans + 1 : 8 * spans * (order - 1) + 1;
  for (int i = 0; i < m; ++i) {
    const double t[1] = {i == m - 1 ? c.hi(0) : c.lo(0) + (c.hi(0) - c.lo(0)) * i / (m - 1)};
    double p[2];
    c.evaluate(t, p);
    out.push_back({p[0], p[1], 0});
  }
  return out;
}

std::vector<Vec3> piece_polyline(const TrimmedSurface::Piece& piece) {
  std::vector<Vec3> line = curve_polyline(piece.curve);
  if (piece.reversed) std::reverse(line.begin(), line.end());
  return line;
}

// Even-odd point in polygon (x, y), rule "at or above counts as above".
bool in_polygon(const std::vector<Vec3>& poly, double x, double y) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[j];
    if ((a.y >= y) != (b.y >= y) && x < a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x)) in = !in;
  }
  return in;
}

// Sutherland-Hodgman: the subject polygon clipped to the half plane left of a -> b.
std::vector<Vec3> clip_edge(const std::vector<Vec3>& poly, Vec3 a, Vec3 b) {
  std::vector<Vec3> out;
  auto side = [&](const Vec3& p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3& p = poly[i];
    const Vec3& q = poly[(i + 1) % poly.size()];
    const double sp = side(p), sq = side(q);
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) out.push_back(p + (sp / (sp - sq)) * (q - p));
  }
  return out;
}

}  // namespace

std::vector<std::vector<Vec3>> trim_loops(const TrimmedSurface& s) {
  std::vector<std::vector<Vec3>> loops;
  const double size = std::hypot(s.surface.hi(0) - s.surface.lo(0), s.surface.hi(1) - s.surface.lo(1));
  for (std::size_t l = 0; l < s.loops.size(); ++l) {
    std::vector<Vec3> poly;
    const auto& loop = s.loops[l];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      if (loop[k].curve.param_dim() != 1 || loop[k].curve.point_dim() != 2)
        throw ModelError(fmt::format("{}: loop {} holds a trimming curve that is not a curve in the surface's (u, v)",
                                     s.name, l + 1));
      std::vector<Vec3> line = piece_polyline(loop[k]);
      if (!poly.empty()) {
        const double d = norm(line.front() - poly.back());
        if (d > 1e-6 * size)
          throw ModelError(
              fmt::format("{}: loop {} is open: segment {} ends at (u, v) = ({:.9g}, {:.9g}) but segment "
                          "{} starts at ({:.9g}, {:.9g})",
                          s.name, l + 1, loop[k - 1].segment + 1, poly.back().x, poly.back().y, loop[k].segment + 1,
                          line.front().x, line.front().y));
        line.erase(line.begin());
      }
      poly.insert(poly.end(), line.begin(), line.end());
    }
    if (poly.size() < 3) throw ModelError(fmt::format("{}: loop {} encloses nothing", s.name, l + 1));
    if (norm(poly.front() - poly.back()) > 1e-6 * size)
      throw ModelError(
          fmt::format("{}: loop {} is open: it ends at (u, v) = ({:.9g}, {:.9g}), not where it starts, "
                      "({:.9g}, {:.9g})",
                      s.name, l + 1, poly.back().x, poly.back().y, poly.front().x, poly.front().y));
    poly.pop_back();
    loops.push_back(std::move(poly));
  }
  return loops;
}

void tessellate_trimmed(const TrimmedSurface& s, int n, std::vector<Vec3>& vertices,
                        std::vector<std::array<int, 3>>& triangles) {
  const std::vector<std::vector<Vec3>> loops = trim_loops(s);
  const double u0 = s.surface.lo(0), u1 = s.surface.hi(0), v0 = s.surface.lo(1), v1 = s.surface.hi(1);
  const double du = (u1 - u0) / (n - 1), dv = (v1 - v0) / (n - 1);
  // Which loops have an edge in each grid cell (a loop edge's box, one cell wider).
  std::map<int, std::vector<int>> touched;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const auto& poly = loops[l];
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Vec3& a = poly[k];
      const Vec3& b = poly[(k + 1) % poly.size()];
      const int i0 = std::clamp(static_cast<int>(std::floor((std::min(a.x, b.x) - u0) / du)) - 1, 0, n - 2);
      const int i1 = std::clamp(static_cast<int>(std::floor((std::max(a.x, b.x) - u0) / du)) + 1, 0, n - 2);
      const int j0 = std::clamp(static_cast<int>(std::floor((std::min(a.y, b.y) - v0) / dv)) - 1, 0, n - 2);
      const int j1 = std::clamp(static_cast<int>(std::floor((std::max(a.y, b.y) - v0) / dv)) + 1, 0, n - 2);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          auto& list = touched[j * (n - 1) + i];
          if (list.empty() || list.back() != static_cast<int>(l)) list.push_back(static_cast<int>(l));
        }
    }
  }
  auto add = [&](const Vec3& p) {
    vertices.push_back(surface_point(s.surface, p.x, p.y));
    return static_cast<int>(vertices.size()) - 1;
  };
  auto add_fan = [&](const std::vector<Vec3>& poly) {
    if (poly.size() < 3) return;
    std::vector<int> idx;
    for (const Vec3& p : poly) idx.push_back(add(p));
    for (std::size_t k = 1; k + 1 < idx.size(); ++k) triangles.push_back({idx[0], idx[k], idx[k + 1]});
  };
  auto grid = [&](int i, int j) { return Vec3{i == n - 1 ? u1 : u0 + du * i, j == n - 1 ? v1 : v0 + dv * j, 0}; };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const Vec3 a = grid(i, j), b = grid(i + 1, j), c = grid(i + 1, j + 1), d = grid(i, j + 1);
      const auto it = touched.find(j * (n - 1) + i);
      for (const std::array<Vec3, 3>& tri : {std::array<Vec3, 3>{a, b, c}, std::array<Vec3, 3>{a, c, d}}) {
        const Vec3 centre = (1.0 / 3.0) * (tri[0] + tri[1] + tri[2]);
        // Loops with no edge here hold the triangle wholly or not at all.
        bool whole = false;
        for (std::size_t l = 0; l < loops.size(); ++l) {
          const bool near = it != touched.end() &&
                            std::find(it->second.begin(), it->second.end(), static_cast<int>(l)) != it->second.end();
          if (!near && in_polygon(loops[l], centre.x, centre.y)) whole = !whole;
        }
        if (whole) add_fan({tri[0], tri[1], tri[2]});
        if (it == touched.end()) continue;
        for (int l : it->second) {
          std::vector<Vec3> poly = loops[static_cast<std::size_t>(l)];
          for (int e = 0; e < 3 && !poly.empty(); ++e)
            poly = clip_edge(poly, tri[static_cast<std::size_t>(e)], tri[static_cast<std::size_t>((e + 1) % 3)]);
          add_fan(poly);
        }
      }
    }
}

double check_trimmed_closed(const TrimShell& shell, double gap) {
  // Every use of each segment: the surface and its curve's points in space.
  struct Use {
    std::size_t surface;
    std::vector<Vec3> points;
  };
  constexpr int kSamples = 65;
  std::map<int, std::vector<Use>> uses;
  for (std::size_t i = 0; i < shell.trimmed.size(); ++i) {
    const TrimmedSurface& s = shell.trimmed[i];
    for (const auto& loop : s.loops)
      for (const auto& piece : loop) {
        Use use{i, {}};
        for (int k = 0; k < kSamples; ++k) {
          // The stored direction, so two uses of one segment sample the same places.
          const double t[1] = {piece.curve.lo(0) + (piece.curve.hi(0) - piece.curve.lo(0)) * k / (kSamples - 1)};
          double uv[2];
          piece.curve.evaluate(t, uv);
          use.points.push_back(surface_point(s.surface, uv[0], uv[1]));
        }
        uses[piece.segment].push_back(std::move(use));
      }
  }
  double worst = 0;
  auto fail = [&](std::size_t surface, int segment, Vec3 at, double d, const std::string& why) {
    throw ModelError(
        fmt::format("{}: {}: trimming segment {} {} ({:.6g} at ({:.6g}, {:.6g}, {:.6g}), more than the "
                    "allowed gap {:.3g}): the surfaces do not close",
                    shell.name, shell.trimmed[surface].name, segment + 1, why, d, at.x, at.y, at.z, gap));
  };
  std::vector<const Use*> seams;
  for (const auto& [segment, list] : uses) {
    if (list.size() == 1) {
      seams.push_back(&list[0]);
      continue;
    }
    for (std::size_t a = 1; a < list.size(); ++a)
      for (int k = 0; k < kSamples; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        const double d = norm(list[a].points[uk] - list[0].points[uk]);
        worst = std::max(worst, d);
        if (d > gap) fail(list[a].surface, segment, list[a].points[uk], d, "lies apart from its other side");
      }
  }
  // A segment on one surface only closes against another such segment: each of its points
  // lies near that one's polyline.
  auto segment_distance = [](Vec3 p, Vec3 a, Vec3 b) {
    const Vec3 ab = b - a;
    const double l2 = dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return norm(p - (a + t * ab));
  };
  for (const auto& [segment, list] : uses) {
    if (list.size() != 1) continue;
    const Use& mine = list[0];
    for (const Vec3& p : mine.points) {
      double best = 1e300;
      for (const Use* other : seams) {
        if (other == &mine) continue;
        for (std::size_t k = 0; k + 1 < other->points.size(); ++k)
          best = std::min(best, segment_distance(p, other->points[k], other->points[k + 1]));
      }
      worst = std::max(worst, best);
      if (best > gap) fail(mine.surface, segment, p, best, "borders one surface and no other segment lies near it");
    }
  }
  return worst;
}

}  // namespace trivox::detail
