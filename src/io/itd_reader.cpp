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
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/itd_parser.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox {

namespace itd {

// Bracket groups whose first word starts an object body rather than an attribute, so an
// object without a name (`[OBJECT [COLOR 2] [SURFACE ...]]`) still has its geometry read.
namespace {
bool starts_body(const Token& t) {
  for (const char* k : {"OBJECT", "TRIVAR", "SURFACE", "CURVE", "TRIMSRF", "MODEL"})
    if (t.is_keyword(k)) return true;
  return false;
}
}  // namespace

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
  while (const std::optional<Token> next = next_group(open, where, " in the object's body")) {
    parse_item(*next, depth);
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

std::optional<Token> ItdParser::next_group(const Token& open, const std::string& where, std::string_view in) {
  const Token t = tok_.next();
  if (t.is_close()) return std::nullopt;
  if (t.is_end()) fail_eof(where, open);
  if (!t.is_open()) fail(t.line, where, fmt::format("unexpected {}{}: expected '[' or ']'", itd::describe(t), in));
  return t;
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
  if (const auto problem = io_detail::model_number_problem(*v, t.text))
    fail(t.line, where, fmt::format("{} {}", what, *problem));
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

}  // namespace itd

Model read_itd(std::string_view text, const std::string& source, const std::atomic<bool>* stop) {
  itd::ItdParser parser(text, source, stop);
  return parser.parse();
}

}  // namespace trivox
