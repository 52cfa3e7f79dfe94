// The spline bodies of an IRIT .itd file: CURVE, SURFACE and TRIVAR, their orders, knot
// vectors and control points (see itd_reader.cpp for the format).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/itd_parser.h"
#include "io/text_number.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox::itd {

void ItdParser::read_geometry(const Token& keyword, int param_dim) {
  const std::string kw = kKeyword[param_dim];
  const std::string where = fmt::format("{} in object '{}'", kw, object_name());
  const std::size_t dims = static_cast<std::size_t>(param_dim);

  const Token basis = tok_.next();
  const bool bezier = basis.is_keyword("BEZIER");
  if (!bezier && !basis.is_keyword("BSPLINE")) {
    if (basis.is_keyword("POWER") || basis.is_keyword("GREGORY"))
      throw UnsupportedError(source_, basis.line, where,
                             fmt::format("{} {} basis is not supported; only BSPLINE and BEZIER are", kw, basis.text));
    fail(line_of(basis), where, fmt::format("expected BSPLINE or BEZIER after {}, found {}", kw, itd::describe(basis)));
  }
  // IRIT allows an attribute group right after the basis keyword.
  while (tok_.peek().is_open() && tok_.peek2().is_word() && !is_number(tok_.peek2())) skip_group(tok_.next());

  std::array<int, 3> counts{1, 1, 1}, orders{1, 1, 1};
  for (std::size_t d = 0; d < dims; ++d)
    counts[d] = read_int(where, fmt::format("number of control points along {}", kDirection[d]), 1, kMaxControlPoints);
  for (std::size_t d = 0; d < dims; ++d) {
    if (bezier) {
      // A Bezier patch's order is its point count.
      orders[d] = counts[d];
      if (orders[d] > kMaxOrder)
        fail(keyword.line, where,
             fmt::format("a Bezier patch with {} points along {} has order {}, above the supported {}", counts[d],
                         kDirection[d], counts[d], kMaxOrder));
    } else {
      orders[d] = read_int(where, fmt::format("order along {}", kDirection[d]), 1, kMaxOrder);
    }
  }

  const Token pt_token = tok_.next();
  PointType pt;
  {
    const std::string_view s = pt_token.text;
    if (!pt_token.is_word() || s.size() != 2 || (s[0] != 'E' && s[0] != 'P' && s[0] != 'e' && s[0] != 'p') ||
        s[1] < '1' || s[1] > '9')
      fail(
          line_of(pt_token), where,
          fmt::format("point type must be E1..E9 (Euclidean) or P1..P9 (rational), found {}", itd::describe(pt_token)));
    pt = PointType{s[1] - '0', s[0] == 'P' || s[0] == 'p', s};
  }

  std::int64_t total = 1;
  for (std::size_t d = 0; d < dims; ++d) {
    const auto next = product_within(total, counts[d], kMaxControlPoints);
    if (!next)
      fail(keyword.line, where,
           fmt::format("declares {} control points, above the limit of {}",
                       fmt::join(std::span(counts).first(dims), " x "), kMaxControlPoints));
    total = *next;
  }

  std::vector<KnotVector> knots;
  for (std::size_t d = 0; d < dims; ++d) {
    if (bezier) {
      try {
        knots.push_back(KnotVector::bezier(orders[d]));
      } catch (const ModelError& e) {
        fail(keyword.line, where, e.what());
      }
    } else {
      knots.push_back(read_knots(where, static_cast<int>(d), counts[d], orders[d]));
    }
  }

  std::vector<double> points, weights;
  for (std::int64_t i = 0; i < total; ++i) read_point(where, i, total, pt, points, weights);
  const Token close = tok_.next();
  if (close.is_open()) fail(close.line, where, fmt::format("more control points than the {} declared", total));
  if (!close.is_close())
    fail(line_of(close), where, fmt::format("expected ']' closing the {}, found {}", kw, itd::describe(close)));

  try {
    TensorSpline spline(std::move(knots), pt.dim, std::move(points), std::move(weights));
    if (const auto problem = io_detail::rational_numbers_problem(spline)) throw ModelError(*problem);
    patches_.push_back(Patch{object_name(), 0, keyword.line, std::move(spline)});
  } catch (const ModelError& e) {
    fail(keyword.line, where, e.what());
  }
}

KnotVector ItdParser::read_knots(const std::string& where, int dir, int num_ctrl, int order) {
  const char* name = kDirection[dir];
  const auto expect_kv = [&](const Token& t) {
    fail(line_of(t), where,
         fmt::format("expected the {} knot vector [KV ...] or [KVP ...], found {}", name, itd::describe(t)));
  };
  const Token open = tok_.next();
  if (!open.is_open()) expect_kv(open);
  const Token kv = tok_.next();
  const bool periodic = kv.is_keyword("KVP");
  if (!periodic && !kv.is_keyword("KV")) expect_kv(kv);
  std::vector<double> values;
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(where, open);
    values.push_back(read_number(t, where, "knot"));
  }
  const std::int64_t expected = periodic ? std::int64_t{num_ctrl} + 2 * order - 1 : std::int64_t{num_ctrl} + order;
  if (static_cast<std::int64_t>(values.size()) != expected)
    fail(open.line, where,
         fmt::format("{} knot vector: {} control points of order {} need {} knots ({}), found {}", name, num_ctrl,
                     order, expected, periodic ? "KVP: n + 2*order - 1" : "KV: n + order", values.size()));
  try {
    return periodic ? KnotVector::periodic(order, num_ctrl, std::move(values)) : KnotVector(order, std::move(values));
  } catch (const ModelError& e) {
    fail(open.line, where, fmt::format("{} knot vector: {}", name, e.what()));
  }
}

void ItdParser::read_point(const std::string& where, std::int64_t index, std::int64_t total, const PointType& pt,
                           std::vector<double>& points, std::vector<double>& weights) {
  const Token open = tok_.next();
  if (open.is_close()) fail(open.line, where, fmt::format("{} control points declared, found only {}", total, index));
  if (!open.is_open())
    fail(line_of(open), where,
         fmt::format("expected '[' starting control point {}, found {}", index, itd::describe(open)));
  const int want = pt.dim + (pt.rational ? 1 : 0);
  std::array<double, 10> v{};
  int n = 0;
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(where, open);
    if (t.is_open()) {
      // An attribute inside a point ([[NORMAL 1 0 0] 1 2 3]) starts with a name; a '[' followed
      // by a number is the next point after a missing ']'.
      if (!tok_.peek().is_word() || is_number(tok_.peek()))
        fail(t.line, where, fmt::format("control point {} is not closed: ']' missing before this '['", index));
      skip_group(t);
      continue;
    }
    const double x = read_number(t, where, "coordinate");
    if (n == want)
      fail(t.line, where,
           fmt::format("control point {} has more than the {} numbers point type {} holds", index, want, pt.name));
    v[static_cast<std::size_t>(n++)] = x;
  }
  if (n != want)
    fail(open.line, where,
         fmt::format("control point {} has {} numbers; point type {} holds {}", index, n, pt.name, want));
  if (!pt.rational) {
    points.insert(points.end(), v.begin(), v.begin() + want);
    return;
  }
  // P<d>: [w, w*x, w*y, ...]; the Euclidean point is the rest divided by w.
  const double w = v[0];
  if (!(w > 0)) fail(open.line, where, fmt::format("control point {} has weight {}; weights must be > 0", index, w));
  for (int c = 1; c < want; ++c) {
    const double x = v[static_cast<std::size_t>(c)] / w;
    if (!std::isfinite(x))
      fail(open.line, where, fmt::format("control point {}: coordinate / weight is not finite (weight {})", index, w));
    points.push_back(x);
  }
  weights.push_back(w);
}

}  // namespace trivox::itd
