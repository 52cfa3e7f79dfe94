// GoTools .g2 reader: SplineCurve (class 100), SplineSurface (200) and SplineVolume (700)
// objects, polynomial or rational, of any order and point dimension; objects of any other
// class are skipped with a note in Model::notes.
//
// Format reference (docs/FORMATS.md, "GoTools .g2"): GoTools' own streaming code,
// gotools-core ObjectHeader::read (class, major and minor version, a count of auxiliary
// integers and the integers), BsplineBasis::read (number of coefficients, ORDER, then
// number + order knots), SplineCurve/SplineSurface/SplineVolume::read (dimension, rational
// flag 0 or 1, one basis per direction, then the coefficients, u fastest; a rational
// coefficient is (w*x, w*y, w*z, w): SplineUtils::make_coef_array_from_rational_coefs divides
// by the last value) and ClassType.h (the class numbers). GoTools reads every value with
// operator>>, so any whitespace separates values and line breaks carry no meaning; the
// reader keeps each value's line only to name it in errors.
//
// An object of another class has no length field: GoTools' reader knows each class's body.
// trivox skips it up to the next line that reads as an object header (a known class number,
// major version 1, a minor version, an auxiliary count and exactly that many integers), or to
// the end of the file.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/text_number.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox {

namespace {

constexpr int kSplineCurve = 100;
constexpr int kSplineSurface = 200;
constexpr int kSplineVolume = 700;
constexpr const char* kDirection[3] = {"u", "v", "w"};

// GoTools' class numbers (gotools-core/include/GoTools/geometry/ClassType.h) and their names,
// for the note on a skipped object and to recognise the header that ends it.
struct ClassName {
  int number;
  const char* name;
};
constexpr ClassName kClasses[] = {
    {100, "SplineCurve"},
    {110, "CurveOnSurface"},
    {111, "CurveOnVolume"},
    {120, "Line"},
    {130, "Circle"},
    {140, "Ellipse"},
    {150, "BoundedCurve"},
    {160, "Hyperbola"},
    {170, "Parabola"},
    {200, "SplineSurface"},
    {210, "BoundedSurface"},
    {211, "SurfaceOnVolume"},
    {220, "GoBaryPolSurface"},
    {230, "GoHBSplineParamSurface"},
    {240, "CompositeSurface"},
    {250, "Plane"},
    {260, "Cylinder"},
    {261, "SurfaceOfLinearExtrusion"},
    {270, "Sphere"},
    {280, "Cone"},
    {290, "Torus"},
    {291, "SurfaceOfRevolution"},
    {292, "Disc"},
    {293, "LRSplineSurface"},
    {294, "TSplineSurface"},
    {300, "Go3dsObject"},
    {310, "GoHeTriang"},
    {320, "GoSdTriang"},
    {330, "GoQuadMesh"},
    {340, "GoHybridMesh"},
    {350, "ParamTriang"},
    {360, "GoVrmlGeometry"},
    {400, "PointCloud"},
    {410, "LineCloud"},
    {500, "GoTriangleSets"},
    {510, "RectGrid"},
    {700, "SplineVolume"},
    {710, "BoundedVolume"},
    {720, "Parallelepiped"},
    {721, "SphereVolume"},
    {722, "CylinderVolume"},
    {723, "ConeVolume"},
    {724, "TorusVolume"},
    {793, "LRSplineVolume"},
};

const char* class_name(std::int64_t number) {
  for (const ClassName& c : kClasses)
    if (c.number == number) return c.name;
  return nullptr;
}

struct Token {
  std::string_view text;
  int line = 0;
};

bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Reads the values one at a time from the text (no token list: a large file costs no more
// memory than the model it holds).
class G2Reader {
 public:
  G2Reader(std::string_view text, const std::string& source, const std::atomic<bool>* stop)
      : text_(text), source_(source), stop_(stop, "reading a model") {}

  Model read();

 private:
  [[noreturn]] void fail(int line, const std::string& where, std::string rule) const {
    throw InputError(source_, line, where, std::move(rule));
  }
  // Moves past blanks (counting lines); a control character is an error.
  void skip_blanks();
  bool at_end() {
    skip_blanks();
    return pos_ >= text_.size();
  }
  // The line of the next value (after skip_blanks).
  int next_line() {
    skip_blanks();
    return line_;
  }
  // The line to name for a value that is missing: the last line that holds something.
  int end_line() const noexcept { return last_line_; }
  Token take(const std::string& where, const std::string& what);
  // How many values follow, counting no further than `limit`; the position does not move.
  std::int64_t values_ahead(std::int64_t limit) const;
  std::int64_t read_int(const std::string& where, const std::string& what, std::int64_t lo, std::int64_t hi);
  double read_double(const std::string& where, const std::string& what);
  // Whether the line starting at `at` reads as a complete object header.
  bool header_line_at(std::size_t at) const;
  void read_object(Model& model, int object);
  KnotVector read_basis(const std::string& where, int dir);
  void skip_object(Model& model, std::int64_t class_number, int line);

  std::string_view text_;
  const std::string& source_;
  StopPoll stop_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int last_line_ = 0;
};

void G2Reader::skip_blanks() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
    } else if (!is_blank(c)) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        fail(line_, "", fmt::format("control character 0x{:02x}: a .g2 file is text", static_cast<unsigned char>(c)));
      return;
    }
    ++pos_;
  }
}

Token G2Reader::take(const std::string& where, const std::string& what) {
  stop_.step();
  if (at_end()) fail(end_line(), where, fmt::format("unexpected end of file: expected {}", what));
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_blank(text_[pos_])) {
    const char c = text_[pos_];
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      fail(line_, "", fmt::format("control character 0x{:02x}: a .g2 file is text", static_cast<unsigned char>(c)));
    ++pos_;
  }
  return {text_.substr(start, pos_ - start), line_};
}

std::int64_t G2Reader::values_ahead(std::int64_t limit) const {
  std::int64_t count = 0;
  std::size_t i = pos_;
  while (count < limit) {
    while (i < text_.size() && is_blank(text_[i])) ++i;
    if (i >= text_.size()) break;
    ++count;
    while (i < text_.size() && !is_blank(text_[i])) ++i;
  }
  return count;
}

std::int64_t G2Reader::read_int(const std::string& where, const std::string& what, std::int64_t lo, std::int64_t hi) {
  const Token t = take(where, what);
  const auto v = io_detail::parse_integer(t.text);
  if (!v) fail(t.line, where, fmt::format("expected {} (an integer), found '{}'", what, t.text));
  if (*v < lo || *v > hi) fail(t.line, where, fmt::format("{} is {}, outside {}..{}", what, *v, lo, hi));
  return *v;
}

double G2Reader::read_double(const std::string& where, const std::string& what) {
  const Token t = take(where, what);
  const auto v = io_detail::parse_double(t.text);
  if (!v) fail(t.line, where, fmt::format("expected {} (a number), found '{}'", what, t.text));
  if (const auto problem = io_detail::model_number_problem(*v, t.text))
    fail(t.line, where, fmt::format("{} {}", what, *problem));
  return *v;
}

bool G2Reader::header_line_at(std::size_t at) const {
  std::int64_t v[4] = {0, 0, 0, 0};
  std::int64_t count = 0;
  std::size_t i = at;
  for (;;) {
    while (i < text_.size() && text_[i] != '\n' && is_blank(text_[i])) ++i;
    if (i >= text_.size() || text_[i] == '\n') break;
    const std::size_t start = i;
    while (i < text_.size() && !is_blank(text_[i])) ++i;
    const auto x = io_detail::parse_integer(text_.substr(start, i - start));
    if (!x) return false;
    if (count < 4) v[count] = *x;
    ++count;
    if (count == 4 &&
        (class_name(v[0]) == nullptr || v[1] != 1 || v[2] < 0 || v[3] < 0 || v[3] > kMaxModelHeaderValues))
      return false;
    if (count > 4 && count > 4 + v[3]) return false;
  }
  return count >= 4 && count == 4 + v[3];
}

Model G2Reader::read() {
  if (text_.find_first_not_of(" \t\r\n\f\v") == std::string_view::npos)
    fail(0, "", "file is empty: a GoTools file holds objects, each starting with a header such as '700 1 0 0'");
  for (std::size_t i = 0; i < text_.size(); ++i) {  // the last line that holds something
    if (!is_blank(text_[i])) last_line_ = line_;
    if (text_[i] == '\n') ++line_;
  }
  line_ = 1;
  Model model{source_, {}, {}};
  int object = 0;
  while (!at_end()) read_object(model, object++);
  if (model.patches.empty())
    fail(0, "",
         fmt::format("the file holds no SplineCurve, SplineSurface or SplineVolume (class 100, 200 or 700); {} "
                     "object{} of other classes skipped",
                     object, object == 1 ? "" : "s"));
  return model;
}

void G2Reader::read_object(Model& model, int object) {
  // ObjectHeader: class, major version, minor version, auxiliary count, auxiliary integers.
  const int line = next_line();
  std::string where = fmt::format("object {}", object);
  const std::int64_t cls = read_int(where, "a class number (the object header's first value)", 0, INT32_MAX);
  const char* name = class_name(cls);
  if (name == nullptr)
    fail(line, where,
         fmt::format("{} is not a GoTools class number (an object starts with its header, e.g. '700 1 0 0' "
                     "for a SplineVolume)",
                     cls));
  where = fmt::format("object {} ({})", object, name);
  const std::int64_t major = read_int(where, "the major version", 0, INT32_MAX);
  if (major != 1)
    fail(line, where,
         fmt::format("version {}: trivox reads GoTools objects of version 1 (the header '{} 1 0 0')", major, cls));
  read_int(where, "the minor version", 0, INT32_MAX);
  const auto aux_count = static_cast<int>(
      read_int(where, "the number of auxiliary header values", 0, static_cast<std::int64_t>(kMaxModelHeaderValues)));
  std::vector<int> aux;
  for (int i = 0; i < aux_count; ++i)
    aux.push_back(static_cast<int>(
        read_int(where, fmt::format("auxiliary header value {} of {}", i + 1, aux_count), INT32_MIN, INT32_MAX)));

  int param_dim = 0;
  if (cls == kSplineCurve) param_dim = 1;
  if (cls == kSplineSurface) param_dim = 2;
  if (cls == kSplineVolume) param_dim = 3;
  if (param_dim == 0) {
    skip_object(model, cls, line);
    return;
  }

  // dimension, rational flag, one basis per direction, coefficients.
  const auto dim = static_cast<int>(read_int(where, "the dimension (coordinates per point)", 1, kMaxModelPointDim));
  const bool rational = read_int(where, "the rational flag (0 or 1)", 0, 1) == 1;
  std::vector<KnotVector> knots;
  std::int64_t total = 1;
  for (int d = 0; d < param_dim; ++d) {
    knots.push_back(read_basis(where, d));
    const std::int64_t n = knots.back().num_ctrl();
    const std::optional<std::int64_t> product = product_within(total, n, kMaxControlPoints);
    if (!product)
      fail(line_, where,
           fmt::format("the bases have {} coefficients together so far, above the limit of {}", total * n,
                       kMaxControlPoints));
    total = *product;
  }
  const int stride = dim + (rational ? 1 : 0);
  const std::int64_t values = total * stride;
  const std::int64_t left = values_ahead(values);
  if (values > left)
    fail(end_line(), where,
         fmt::format("the file ends after {} of the {} coefficient values ({} {} of {} value{}){}", left, values, total,
                     rational ? "rational points" : "points", stride, stride == 1 ? "" : "s",
                     rational ? ": a rational point is w*x, w*y, ..., w" : ""));
  std::vector<double> points, weights;
  points.reserve(static_cast<std::size_t>(total * dim));
  if (rational) weights.reserve(static_cast<std::size_t>(total));
  std::vector<double> h(static_cast<std::size_t>(stride));
  for (std::int64_t i = 0; i < total; ++i) {
    const int point_line = next_line();
    for (int c = 0; c < stride; ++c)
      h[static_cast<std::size_t>(c)] =
          read_double(where, fmt::format("value {} of coefficient {} (0-based, u fastest)", c + 1, i));
    if (!rational) {
      points.insert(points.end(), h.begin(), h.end());
      continue;
    }
    const double w = h.back();
    if (!(w > 0))
      fail(point_line, where, fmt::format("coefficient {} has weight {} (its last value); weights must be > 0", i, w));
    for (int c = 0; c < dim; ++c) {
      const double x = h[static_cast<std::size_t>(c)] / w;
      if (!std::isfinite(x))
        fail(point_line, where,
             fmt::format("coefficient {}: coordinate {} / weight {} overflows", i, h[static_cast<std::size_t>(c)], w));
      points.push_back(x);
    }
    weights.push_back(w);
  }
  try {
    TensorSpline spline(std::move(knots), dim, std::move(points), std::move(weights));
    if (const auto problem = io_detail::rational_numbers_problem(spline)) throw ModelError(*problem);
    const int index = static_cast<int>(model.patches.size());
    Patch patch{fmt::format("{} #{}", name, object), index, line, std::move(spline)};
    patch.header_aux = std::move(aux);
    model.patches.push_back(std::move(patch));
  } catch (const ModelError& e) {
    fail(line, where, e.what());
  }
}

KnotVector G2Reader::read_basis(const std::string& where, int dir) {
  const char* d = kDirection[dir];
  const int line = at_end() ? end_line() : next_line();
  const auto n = read_int(where, fmt::format("the number of coefficients along {}", d), 1, kMaxControlPoints);
  const auto order = static_cast<int>(read_int(where, fmt::format("the order along {} (degree + 1)", d), 1, INT32_MAX));
  if (order > kMaxOrder)
    fail(line, where, fmt::format("order {} along {}: trivox evaluates orders up to {}", order, d, kMaxOrder));
  if (n < order)
    fail(line, where,
         fmt::format("{} coefficients along {} with order {}: a basis has at least as many coefficients as its order",
                     n, d, order));
  const std::int64_t count = n + order;
  if (values_ahead(count) < count)
    fail(end_line(), where,
         fmt::format("the file ends within the {} knots along {} ({} coefficients + order {})", count, d, n, order));
  std::vector<double> knots;
  knots.reserve(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i)
    knots.push_back(read_double(where, fmt::format("knot {} of {} along {}", i + 1, count, d)));
  try {
    return KnotVector(order, std::move(knots));
  } catch (const ModelError& e) {
    fail(line, where, fmt::format("the knots along {}: {}", d, e.what()));
  }
}

void G2Reader::skip_object(Model& model, std::int64_t class_number, int line) {
  // Up to the first line after the header's that reads as a header, or to the end.
  int last_line = line;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  while (pos_ < text_.size()) {
    ++pos_;  // past the '\n'
    ++line_;
    if (header_line_at(pos_)) break;
    const std::size_t eol = std::min(text_.find('\n', pos_), text_.size());
    if (text_.substr(pos_, eol - pos_).find_first_not_of(" \t\r\f\v") != std::string_view::npos) last_line = line_;
    pos_ = eol;
  }
  model.notes.push_back(ModelNote{
      line, fmt::format("skipped a {} (class {}, lines {} to {}): trivox reads SplineCurve, SplineSurface and "
                        "SplineVolume objects",
                        class_name(class_number), class_number, line, last_line)});
}

}  // namespace

Model read_g2(std::string_view text, const std::string& source, const std::atomic<bool>* stop) {
  G2Reader reader(text, source, stop);
  return reader.read();
}

}  // namespace trivox
