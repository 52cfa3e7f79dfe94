// GoTools .g2 writer: one object per patch, in the layout GoTools' own write functions use
// (header line; dimension and rational flag; per direction the coefficient count and order,
// then the knots; one coefficient per line, u fastest). See g2_reader.cpp for the format's
// sources and docs/FORMATS.md for the rules.
#include <cmath>
#include <iterator>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {

namespace {

constexpr int kClassByParamDim[4] = {0, 100, 200, 700};  // SplineCurve, SplineSurface, SplineVolume

// The homogeneous coordinate stored for x with weight w: w * x, or a neighbour of it within a
// few ulps whose quotient by w is x again, so that the reader (which divides) gets x back
// bit for bit. Such a neighbour does not exist for every x and w (the quotients of adjacent
// doubles may skip x); then w * x, which reads back within an ulp or two.
double homogeneous(double x, double w) {
  double c = w * x;
  // x = c0 / w for a finite c0 near the largest double may give w * x = infinity.
  if (!std::isfinite(c)) c = std::copysign(std::numeric_limits<double>::max(), x);
  if (c / w == x) return c;
  double below = c, above = c;
  for (int step = 0; step < 4; ++step) {
    below = std::nextafter(below, -std::numeric_limits<double>::infinity());
    if (below / w == x) return below;
    above = std::nextafter(above, std::numeric_limits<double>::infinity());
    if (above / w == x) return above;
  }
  return c;
}

// The knots of one direction as GoTools stores them, and the control index of each basis
// function: a periodic direction becomes the unclamped basis it evaluates as.
struct Direction {
  std::vector<int> ctrl;  // per basis function: the control point along this direction
  const KnotVector* knots;
};

void write_patch(std::string& buf, const Patch& patch) {
  const TensorSpline& s = patch.spline;
  const int dims = s.param_dim();
  auto out = std::back_inserter(buf);
  fmt::format_to(out, "{} 1 0 {}", kClassByParamDim[dims], patch.header_aux.size());
  for (int a : patch.header_aux) fmt::format_to(out, " {}", a);
  fmt::format_to(out, "\n{} {}\n", s.point_dim(), s.is_rational() ? 1 : 0);

  Direction dir[3];
  for (int d = 0; d < 3; ++d) {
    if (d >= dims) {
      dir[d].ctrl = {0};
      dir[d].knots = nullptr;
      continue;
    }
    const KnotVector& kv = s.knots(d);
    dir[d].knots = &kv;
    for (int i = 0; i < kv.num_basis(); ++i) dir[d].ctrl.push_back(kv.ctrl_index(i));
    fmt::format_to(out, "{} {}\n", kv.num_basis(), kv.order());
    const auto k = kv.knots();
    for (std::size_t i = 0; i < k.size(); ++i) fmt::format_to(out, "{}{}", i > 0 ? " " : "", k[i]);
    buf += '\n';
  }

  for (int kk : dir[2].ctrl)
    for (int jj : dir[1].ctrl)
      for (int ii : dir[0].ctrl) {
        const auto p = s.point(ii, jj, kk);
        if (s.is_rational()) {
          const double w = s.weight(ii, jj, kk);
          for (double x : p) fmt::format_to(out, "{} ", homogeneous(x, w));
          fmt::format_to(out, "{}\n", w);
        } else {
          for (std::size_t c = 0; c < p.size(); ++c) fmt::format_to(out, "{}{}", c > 0 ? " " : "", p[c]);
          buf += '\n';
        }
      }
  buf += '\n';
}

}  // namespace

void write_g2(std::ostream& out, const Model& model) {
  std::string buf;
  for (const Patch& patch : model.patches) {
    buf.clear();
    write_patch(buf, patch);
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (!out) throw IoError(fmt::format("writing GoTools text for '{}' failed", model.source));
  }
  out.flush();
  if (!out) throw IoError(fmt::format("writing GoTools text for '{}' failed", model.source));
}

}  // namespace trivox
