// IRIT text (.itd) reader: CURVE, SURFACE and TRIVAR objects, B-spline or Bezier, Euclidean
// (E<d>) or rational (P<d>). Everything else IRIT can store (polygons, matrices, strings,
// instances, multivariates, triangular surfaces...) is skipped as a balanced bracket group.
// Trimmed surfaces (TRIMSRF, MODEL) contribute their untrimmed surfaces. A MODEL's structure
// (trimmed surfaces MDLTSRF with loops MDLLOOP of trimming segments MDLTSEG, each segment a
// curve in the parameters of each surface it borders) is kept in Model::trimmed_models;
// TRIMSRF trimming curves are skipped.
//
// Format reference: IRIT's own parser (prsr_lib/iritprs1.c, bsp_read.c, trivread.c): orders
// (degree + 1) follow the point counts, a periodic [KVP holds n + 2*order - 1 knots, and
// rational points are written weight first with pre-multiplied coordinates [w w*x w*y w*z].
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/itd_tokenizer.h"
#include "io/text_number.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox {

namespace {

using itd::Token;
using itd::Tokenizer;

// Limits that turn corrupt or hostile headers into errors before anything is allocated.
constexpr int kMaxNesting = 1000;  // objects (and models) inside objects
constexpr const char* kDirection[3] = {"u", "v", "w"};
constexpr const char* kKeyword[4] = {"", "CURVE", "SURFACE", "TRIVAR"};

struct PointType {
  int dim = 3;
  bool rational = false;
  std::string_view name;
};

class ItdParser {
 public:
  ItdParser(std::string_view text, const std::string& source) : text_(text), tok_(text, source), source_(source) {}

  Model parse();

 private:
  [[noreturn]] void fail(int line, const std::string& where, std::string rule) const {
    throw InputError(source_, line, where, std::move(rule));
  }
  // The line to report for a token: where the file stops when the token is its end.
  int line_of(const Token& t) const noexcept { return t.is_end() ? tok_.last_line() : t.line; }
  [[noreturn]] void fail_eof(const std::string& where, const Token& open) const {
    fail(tok_.last_line(), where,
         fmt::format("unexpected end of file: the '[' opened at line {} is never closed", open.line));
  }

  void parse_item(const Token& open, int depth);
  void parse_object(const Token& open, int depth);
  void parse_trimmed(const Token& open, int depth);
  // Kept out of parse_item, which recurses once per nested object: inlined there, a MODEL's
  // locals would grow every level's stack frame (AddressSanitizer's frames overflowed the
  // stack before the nesting limit).
  [[gnu::noinline]] void parse_model(const Token& open);
  void parse_model_surface(const Token& open, TrimmedModel& model, const std::string& where);
  void parse_model_segment(const Token& open, TrimmedModel& model, const std::string& where);
  void skip_group(const Token& open);
  void read_geometry(const Token& keyword, int param_dim);
  KnotVector read_knots(const std::string& where, int dir, int num_ctrl, int order);
  void read_point(const std::string& where, std::int64_t index, std::int64_t total, const PointType& pt,
                  std::vector<double>& points, std::vector<double>& weights);
  double read_number(const Token& t, const std::string& where, const char* what) const;
  int read_int(const std::string& where, const std::string& what, std::int64_t lo, std::int64_t hi);
  std::string object_name() const;

  std::string_view text_;
  Tokenizer tok_;
  const std::string& source_;
  std::vector<std::string> names_;  // names of the enclosing objects, outermost first
  std::vector<Patch> patches_;
  std::vector<TrimmedModel> models_;
};

// Bracket groups whose first word starts an object body rather than an attribute, so an
// object without a name (`[OBJECT [COLOR 2] [SURFACE ...]]`) still has its geometry read.
bool starts_body(const Token& t) {
  for (const char* k : {"OBJECT", "TRIVAR", "SURFACE", "CURVE", "TRIMSRF", "MODEL"})
    if (t.is_keyword(k)) return true;
  return false;
}

bool is_number(const Token& t) { return t.is_word() && io_detail::parse_double(t.text).has_value(); }

Model ItdParser::parse() {
  if (text_.find_first_not_of(" \t\r\n\f\v") == std::string_view::npos)
    fail(0, "", "file is empty: an IRIT file holds [OBJECT ...] groups");
  for (Token t = tok_.next(); !t.is_end(); t = tok_.next()) {
    if (t.is_open()) {
      parse_item(t, 0);
    } else if (t.is_close()) {
      fail(t.line, "", "unmatched ']': no '[' is open here");
    } else {
      fail(t.line, "", fmt::format("expected '[' starting an object, found {}", itd::describe(t)));
    }
  }
  if (patches_.empty()) fail(0, "", "the file holds no CURVE, SURFACE or TRIVAR object");

  // Several patches read under one name (an object holding several surfaces, a MODEL, or
  // equal names) get " #k" so each name in the model is unique.
  std::map<std::string, int> uses, seen;
  for (const Patch& p : patches_) ++uses[p.name];
  for (std::size_t i = 0; i < patches_.size(); ++i) {
    Patch& p = patches_[i];
    p.id = static_cast<int>(i);
    if (uses[p.name] > 1) p.name = fmt::format("{} #{}", p.name, seen[p.name]++);
  }
  return Model{source_, std::move(patches_), std::move(models_)};
}

void ItdParser::parse_item(const Token& open, int depth) {
  const Token k = tok_.peek();
  if (k.is_keyword("OBJECT")) {
    tok_.next();
    parse_object(open, depth + 1);
  } else if (k.is_keyword("TRIVAR") || k.is_keyword("SURFACE") || k.is_keyword("CURVE")) {
    tok_.next();
    read_geometry(k, k.is_keyword("TRIVAR") ? 3 : (k.is_keyword("SURFACE") ? 2 : 1));
  } else if (k.is_keyword("MODEL")) {
    tok_.next();
    parse_model(open);
  } else if (k.is_keyword("TRIMSRF")) {
    tok_.next();
    parse_trimmed(open, depth + 1);
  } else {
    skip_group(open);
  }
}

void ItdParser::parse_object(const Token& open, int depth) {
  if (depth > kMaxNesting) fail(open.line, "", fmt::format("objects nested more than {} deep", kMaxNesting));
  // [OBJECT [attr ...]* NAME body* ]: attributes stand before the name.
  std::string name;
  for (;;) {
    const Token t = tok_.peek();
    if (t.is_open() && !starts_body(tok_.peek2())) {
      tok_.next();
      skip_group(t);
      continue;
    }
    if (t.is_word() || t.kind == itd::TokenKind::kString) {
      name = std::string(t.text);
      tok_.next();
    }
    break;
  }
  names_.push_back(name);
  const std::string where = fmt::format("object '{}'", name);
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(where, open);
    if (!t.is_open())
      fail(t.line, where, fmt::format("unexpected {} in the object's body: expected '[' or ']'", itd::describe(t)));
    parse_item(t, depth);
  }
  names_.pop_back();
}

// TRIMSRF, MODEL and MDLTSRF: read the SURFACE objects, descend into MDLTSRF, skip the rest
// (trimming curves, MDLTSEG segments, MDLLOOP loops and the counts between them).
void ItdParser::parse_trimmed(const Token& open, int depth) {
  if (depth > kMaxNesting) fail(open.line, "", fmt::format("objects nested more than {} deep", kMaxNesting));
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) return;
    if (t.is_end()) fail_eof("trimmed surface", open);
    if (!t.is_open()) continue;
    const Token k = tok_.peek();
    if (k.is_keyword("SURFACE")) {
      tok_.next();
      read_geometry(k, 2);
    } else if (k.is_keyword("MDLTSRF")) {
      tok_.next();
      parse_trimmed(t, depth + 1);
    } else {
      skip_group(t);
    }
  }
}

// [MODEL n_surfaces n_segments [MDLTSRF ...]* [MDLTSEG ...]* ]; segment and surface
// references are 1-based in the file, 0-based once read.
void ItdParser::parse_model(const Token& open) {
  const std::string where = fmt::format("MODEL in object '{}'", object_name());
  TrimmedModel model;
  model.name = object_name();
  model.source_line = open.line;
  const int num_surfaces = read_int(where, "number of trimmed surfaces", 0, 10'000'000);
  const int num_segments = read_int(where, "number of trimming segments", 0, 10'000'000);
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(where, open);
    if (!t.is_open())
      fail(t.line, where, fmt::format("unexpected {} in the MODEL: expected '[' or ']'", itd::describe(t)));
    const Token k = tok_.peek();
    if (k.is_keyword("MDLTSRF")) {
      tok_.next();
      parse_model_surface(t, model, where);
    } else if (k.is_keyword("MDLTSEG")) {
      tok_.next();
      parse_model_segment(t, model, where);
    } else {
      skip_group(t);
    }
  }
  if (static_cast<int>(model.surfaces.size()) != num_surfaces)
    fail(open.line, where,
         fmt::format("the MODEL declares {} trimmed surfaces (MDLTSRF) and holds {}", num_surfaces,
                     model.surfaces.size()));
  if (static_cast<int>(model.segments.size()) != num_segments)
    fail(open.line, where,
         fmt::format("the MODEL declares {} trimming segments (MDLTSEG) and holds {}", num_segments,
                     model.segments.size()));
  for (std::size_t g = 0; g < model.segments.size(); ++g) {
    TrimmedModel::Segment& seg = model.segments[g];
    for (int& srf : seg.surfaces) {
      if (srf < 1 || srf > num_surfaces)
        fail(seg.source_line, where,
             fmt::format("trimming segment {} borders surface {}, but the MODEL's surfaces are "
                         "1..{}",
                         g + 1, srf, num_surfaces));
      --srf;
    }
  }
  for (std::size_t i = 0; i < model.surfaces.size(); ++i)
    for (const auto& loop : model.surfaces[i].loops)
      for (int ref : loop) {
        const int g = std::abs(ref);
        if (g < 1 || g > num_segments)
          fail(model.surfaces[i].source_line, where,
               fmt::format("a loop of trimmed surface {} refers to segment {}, but the MODEL's segments are 1..{}",
                           i + 1, ref, num_segments));
      }
  models_.push_back(std::move(model));
}

// [MDLTSRF n_loops [SURFACE ...] [MDLLOOP ref ...]* ]
void ItdParser::parse_model_surface(const Token& open, TrimmedModel& model, const std::string& where) {
  const std::string here = fmt::format("{}, trimmed surface {}", where, model.surfaces.size() + 1);
  TrimmedModel::Surface srf;
  srf.source_line = open.line;
  const int num_loops = read_int(here, "number of loops", 0, 10'000'000);
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(here, open);
    if (!t.is_open()) fail(t.line, here, fmt::format("unexpected {}: expected '[' or ']'", itd::describe(t)));
    const Token k = tok_.peek();
    if (k.is_keyword("SURFACE")) {
      tok_.next();
      if (srf.patch >= 0) fail(k.line, here, "a trimmed surface (MDLTSRF) holds one SURFACE; this is a second");
      read_geometry(k, 2);
      srf.patch = static_cast<int>(patches_.size()) - 1;
    } else if (k.is_keyword("MDLLOOP")) {
      tok_.next();
      std::vector<int> loop;
      for (;;) {
        const Token r = tok_.next();
        if (r.is_close()) break;
        if (r.is_end()) fail_eof(here, t);
        const auto v = r.is_word() ? io_detail::parse_integer(r.text) : std::nullopt;
        if (!v || *v == 0 || *v > 10'000'000 || *v < -10'000'000)
          fail(r.line, here,
               fmt::format("a loop (MDLLOOP) lists segment numbers (1-based, negative for reversed), "
                           "found {}",
                           itd::describe(r)));
        loop.push_back(static_cast<int>(*v));
      }
      if (loop.empty()) fail(t.line, here, "a loop (MDLLOOP) lists no segment");
      srf.loops.push_back(std::move(loop));
    } else {
      skip_group(t);
    }
  }
  if (srf.patch < 0) fail(open.line, here, "a trimmed surface (MDLTSRF) holds no SURFACE");
  if (static_cast<int>(srf.loops.size()) != num_loops)
    fail(open.line, here, fmt::format("declares {} loops and holds {}", num_loops, srf.loops.size()));
  model.surfaces.push_back(std::move(srf));
}

// [MDLTSEG mask surface_1 surface_2 [CURVE ...]* ]: the mask's bits say which curves follow,
// in this order: 1 the curve in surface_1's (u, v), 2 the one in surface_2's, 4 the curve in
// space (IRIT's prsr_lib). surface_2 is 0 for a segment on one surface only.
void ItdParser::parse_model_segment(const Token& open, TrimmedModel& model, const std::string& where) {
  const std::string here = fmt::format("{}, trimming segment {}", where, model.segments.size() + 1);
  TrimmedModel::Segment seg;
  seg.source_line = open.line;
  const int mask = read_int(here, "curve mask", 0, 7);
  const int first = read_int(here, "first surface", 0, 10'000'000);
  const int second = read_int(here, "second surface", 0, 10'000'000);
  if ((mask & 1) && first == 0) fail(open.line, here, "the curve mask has a curve in the first surface, which is 0");
  if ((mask & 2) && second == 0) fail(open.line, here, "the curve mask has a curve in the second surface, which is 0");
  std::vector<TensorSpline> curves;
  std::vector<int> lines;
  for (;;) {
    const Token t = tok_.next();
    if (t.is_close()) break;
    if (t.is_end()) fail_eof(here, open);
    if (!t.is_open()) fail(t.line, here, fmt::format("unexpected {}: expected '[' or ']'", itd::describe(t)));
    const Token k = tok_.peek();
    if (k.is_keyword("CURVE")) {
      tok_.next();
      read_geometry(k, 1);
      curves.push_back(std::move(patches_.back().spline));
      lines.push_back(k.line);
      patches_.pop_back();
    } else {
      skip_group(t);
    }
  }
  const int expected = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1);
  if (static_cast<int>(curves.size()) != expected)
    fail(open.line, here,
         fmt::format("the curve mask {} announces {} curve(s) (1: in the first surface's (u, v), 2: in "
                     "the second's, 4: in space) and the segment holds {}",
                     mask, expected, curves.size()));
  std::size_t next = 0;
  for (const auto& [bit, surface] : {std::pair{1, first}, std::pair{2, second}}) {
    if (!(mask & bit)) continue;
    if (curves[next].point_dim() != 2)
      fail(lines[next], here,
           fmt::format("a trimming curve lies in a surface's parameter space (2 coordinates), this "
                       "one has {}",
                       curves[next].point_dim()));
    seg.surfaces.push_back(surface);
    seg.curves.push_back(std::move(curves[next++]));
  }
  model.segments.push_back(std::move(seg));
}

// Consumes a bracket group whose '[' was read, whatever it holds. Iterative, so deep
// nesting in a skipped group cannot exhaust the stack.
void ItdParser::skip_group(const Token& open) {
  for (int depth = 1; depth > 0;) {
    const Token t = tok_.next();
    if (t.is_open()) ++depth;
    if (t.is_close()) --depth;
    if (t.is_end()) fail_eof("", open);
  }
}

std::string ItdParser::object_name() const {
  // IRIT names unnamed objects NONE: use the nearest enclosing object with a real name.
  for (auto it = names_.rbegin(); it != names_.rend(); ++it)
    if (!it->empty() && *it != "NONE" && *it != "none") return *it;
  return "patch";
}

double ItdParser::read_number(const Token& t, const std::string& where, const char* what) const {
  if (!t.is_word()) fail(line_of(t), where, fmt::format("expected a {}, found {}", what, itd::describe(t)));
  const auto v = io_detail::parse_double(t.text);
  if (!v) fail(t.line, where, fmt::format("{} '{}' is not a number", what, t.text));
  if (!std::isfinite(*v))
    fail(t.line, where, fmt::format("{} '{}' is not finite (NaN and infinity are not allowed)", what, t.text));
  return *v;
}

int ItdParser::read_int(const std::string& where, const std::string& what, std::int64_t lo, std::int64_t hi) {
  const Token t = tok_.next();
  if (!t.is_word()) fail(line_of(t), where, fmt::format("expected the {}, found {}", what, itd::describe(t)));
  const auto v = io_detail::parse_integer(t.text);
  if (!v) fail(t.line, where, fmt::format("the {} must be an integer, found '{}'", what, t.text));
  if (*v < lo || *v > hi) fail(t.line, where, fmt::format("the {} is {}, outside {}..{}", what, *v, lo, hi));
  return static_cast<int>(*v);
}

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

}  // namespace

Model read_itd(std::string_view text, const std::string& source) {
  ItdParser parser(text, source);
  return parser.parse();
}

}  // namespace trivox
