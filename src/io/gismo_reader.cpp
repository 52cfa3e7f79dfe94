// G+Smo XML reader: tensor-product B-spline and NURBS geometry (curves, surfaces,
// trivariates) under an <xml> root.
//
// Which <Geometry> elements are patches: those a <MultiPatch> lists (by id range or id list)
// when the file has one; otherwise every <Geometry> directly under the root, plus the
// surface of each <TrimSurface> (its trimming curves are skipped), in document order. Such
// files may repeat ids or leave them out, so document order, not ids, is the patch order.
//
// Format reference: G+Smo's gsXml readers (gsNurbs/gsKnotVector.hpp, gsTensorBSplineBasis,
// gsTensorNurbsBasis, gsIO/gsBase64.h). `degree` is the degree (order - 1); child bases of a
// tensor basis count in document order (their `index` attributes are not trusted); NURBS
// weights sit beside the inner basis, before or after it; coefs are Euclidean points.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "io/gismo_xml.h"
#include "io/text_number.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox {

namespace {

using io_detail::only_child;
using io_detail::XmlContext;

constexpr std::int64_t kMaxRangePatches = 1'000'000;  // patches one id_range may list
constexpr std::int64_t kIntMin = std::numeric_limits<int>::min();
constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();

struct GeometryType {
  const char* name;
  int param_dim;
  bool rational;
};
constexpr GeometryType kGeometryTypes[] = {
    {"BSpline", 1, false},        {"Nurbs", 1, true},        {"TensorBSpline2", 2, false},
    {"TensorBSpline3", 3, false}, {"TensorNurbs2", 2, true}, {"TensorNurbs3", 3, true},
};

// Basis labels are checked for their kind only: the structure (child bases, weights) fixes
// the dimension, as in G+Smo, which reads lshape_thick_C0.xml's TensorNurbs3 although its
// basis calls itself TensorNurbsBasis2.
bool is_bspline_basis(std::string_view type) {
  return type == "BSplineBasis" || type.substr(0, 18) == "TensorBSplineBasis";
}
bool is_nurbs_basis(std::string_view type) { return type == "NurbsBasis" || type.substr(0, 16) == "TensorNurbsBasis"; }

bool is_hierarchical(std::string_view type) {
  return type.find("THB") != std::string_view::npos || type.substr(0, 2) == "HB";
}

class GismoReader {
 public:
  GismoReader(std::string_view text, const std::string& source, const std::atomic<bool>* stop)
      : text_(text), ctx_(text, source, stop), stop_(stop) {}

  Model read();

 private:
  std::vector<std::pair<pugi::xml_node, pugi::xml_node>> select_patches(pugi::xml_node root) const;
  std::vector<std::int64_t> listed_ids(pugi::xml_node patches) const;
  TensorSpline read_geometry(pugi::xml_node geometry) const;
  // The knot vectors of a basis; `functions` counts the basis functions of those read so far
  // and none may take it past `most` (checked before a knot vector is built).
  std::vector<KnotVector> read_bspline_basis(pugi::xml_node basis, int dim, std::int64_t most) const;
  KnotVector read_knot_vector(pugi::xml_node kv, std::int64_t& functions, std::int64_t most) const;
  std::int64_t int_attribute(pugi::xml_node node, const char* name, std::int64_t lo, std::int64_t hi) const;

  std::string_view text_;
  XmlContext ctx_;
  const std::atomic<bool>* stop_;
};

Model GismoReader::read() {
  const std::string& source = ctx_.source();
  if (text_.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw InputError(source, 0, "", "file is empty: a G+Smo file holds an <xml> element");
  pugi::xml_document doc;
  // Comments before the <?xml ...?> declaration (six of the G+Smo files have one) are not
  // well-formed XML; pugixml skips the declaration wherever it stands, so they read fine.
  const pugi::xml_parse_result parsed =
      doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
  throw_if_stopped(stop_, "reading a model");
  if (!parsed)
    throw InputError(source, ctx_.line_at(parsed.offset), "",
                     fmt::format("XML syntax error: {}", parsed.description()));
  const pugi::xml_node root = doc.document_element();
  if (!root) throw InputError(source, 0, "", "the file holds no XML element");
  if (std::string_view(root.name()) != "xml")
    ctx_.fail(root, fmt::format("the root element must be <xml>, found <{}>", root.name()));

  Model model{source, {}, {}};
  for (const auto& [geometry, label] : select_patches(root)) {
    const int index = static_cast<int>(model.patches.size());
    int id = index;
    std::string name = fmt::format("{} #{}", label.name(), index);
    if (label.attribute("id")) {
      id = static_cast<int>(int_attribute(label, "id", kIntMin, kIntMax));
      name = fmt::format("{} id={}", label.name(), id);
    }
    model.patches.push_back(Patch{std::move(name), id, ctx_.line_of(geometry), read_geometry(geometry)});
  }
  return model;
}

// (geometry element, element that names it: the Geometry itself or its TrimSurface).
std::vector<std::pair<pugi::xml_node, pugi::xml_node>> GismoReader::select_patches(pugi::xml_node root) const {
  std::vector<std::pair<pugi::xml_node, pugi::xml_node>> out;
  if (!root.child("MultiPatch")) {
    for (pugi::xml_node child : root.children()) {
      if (std::string_view(child.name()) == "Geometry") out.emplace_back(child, child);
      if (std::string_view(child.name()) == "TrimSurface")
        if (const pugi::xml_node g = child.child("Geometry")) out.emplace_back(g, child);
    }
    if (out.empty()) ctx_.fail(root, "the file holds no <Geometry> element");
    return out;
  }
  std::multimap<std::int64_t, pugi::xml_node> by_id;
  for (pugi::xml_node g : root.children("Geometry"))
    if (g.attribute("id")) by_id.emplace(int_attribute(g, "id", kIntMin, kIntMax), g);
  std::set<std::int64_t> taken;
  for (pugi::xml_node mp : root.children("MultiPatch")) {
    const pugi::xml_node patches = only_child(ctx_, mp, "patches");
    for (std::int64_t id : listed_ids(patches)) {
      if (!taken.insert(id).second) ctx_.fail(patches, fmt::format("patch id {} is listed twice", id));
      const auto [first, last] = by_id.equal_range(id);
      if (first == last)
        ctx_.fail(patches, fmt::format("the MultiPatch lists patch id {}, but no <Geometry id=\"{}\"> exists", id, id));
      if (std::next(first) != last)
        ctx_.fail(std::next(first)->second,
                  fmt::format("several <Geometry> elements have id {}, which the MultiPatch lists", id));
      out.emplace_back(first->second, first->second);
    }
  }
  return out;
}

std::vector<std::int64_t> GismoReader::listed_ids(pugi::xml_node patches) const {
  std::vector<std::int64_t> ids;
  for (double v : ctx_.read_values(patches)) {
    if (v != std::floor(v) || std::abs(v) > static_cast<double>(kIntMax))
      ctx_.fail(patches, fmt::format("patch id {} is not an integer", v));
    ids.push_back(static_cast<std::int64_t>(v));
  }
  const std::string_view type = patches.attribute("type").value();
  if (type == "id_index") return ids;
  if (type != "id_range")
    ctx_.fail(patches, fmt::format("patches type '{}' is unknown (expected id_range or id_index)", type));
  if (ids.size() != 2 || ids[0] > ids[1]) ctx_.fail(patches, "an id_range holds two ids, first <= last");
  if (ids[1] - ids[0] >= kMaxRangePatches)
    ctx_.fail(patches, fmt::format("the id range {}..{} lists more than {} patches", ids[0], ids[1], kMaxRangePatches));
  std::vector<std::int64_t> range;
  for (std::int64_t id = ids[0]; id <= ids[1]; ++id) range.push_back(id);
  return range;
}

std::int64_t GismoReader::int_attribute(pugi::xml_node node, const char* name, std::int64_t lo, std::int64_t hi) const {
  const pugi::xml_attribute a = node.attribute(name);
  if (!a) ctx_.fail(node, fmt::format("<{}> has no {} attribute", node.name(), name));
  const auto v = io_detail::parse_integer(a.value());
  if (!v) ctx_.fail(node, fmt::format("{}=\"{}\" is not an integer", name, a.value()));
  if (*v < lo || *v > hi) ctx_.fail(node, fmt::format("{}={} is outside {}..{}", name, *v, lo, hi));
  return *v;
}

TensorSpline GismoReader::read_geometry(pugi::xml_node geometry) const {
  const std::string_view type = geometry.attribute("type").value();
  if (type.empty()) ctx_.fail(geometry, "<Geometry> has no type attribute");
  if (is_hierarchical(type))
    ctx_.unsupported(geometry, fmt::format("{} is a hierarchical (THB) spline, which trivox does not read: "
                                           "convert it to a tensor-product B-spline or NURBS",
                                           type));
  const GeometryType* gt = nullptr;
  for (const GeometryType& candidate : kGeometryTypes)
    if (type == candidate.name) gt = &candidate;
  if (gt == nullptr)
    ctx_.unsupported(geometry, fmt::format("Geometry type '{}' is not supported (supported: BSpline, Nurbs, "
                                           "TensorBSpline2/3, TensorNurbs2/3)",
                                           type));
  const int dim = gt->param_dim;

  // A NURBS basis wraps a B-spline basis and the weights, in either order.
  const pugi::xml_node basis = only_child(ctx_, geometry, "Basis");
  const std::string_view basis_type = basis.attribute("type").value();
  if (is_hierarchical(basis_type))
    ctx_.unsupported(basis, fmt::format("{} is a hierarchical (THB) basis, which trivox does not read", basis_type));
  if (gt->rational ? !is_nurbs_basis(basis_type) : !is_bspline_basis(basis_type))
    ctx_.fail(basis, fmt::format("a {} geometry needs a {} basis, found type '{}'", type,
                                 gt->rational ? "NURBS (TensorNurbsBasis<d>)" : "B-spline (TensorBSplineBasis<d>)",
                                 basis_type));
  // The coefficients first: a basis has at most one function per number they hold, so a
  // knot vector given by its size alone (mode="uniform") is checked against them before it
  // is built.
  const pugi::xml_node coefs = only_child(ctx_, geometry, "coefs");
  std::vector<double> values = ctx_.read_values(coefs);
  const std::int64_t most = std::min<std::int64_t>(kMaxControlPoints, static_cast<std::int64_t>(values.size()));
  std::vector<KnotVector> knots;
  std::vector<double> weights;
  pugi::xml_node weights_node;
  if (gt->rational) {
    knots = read_bspline_basis(only_child(ctx_, basis, "Basis"), dim, most);
    weights_node = only_child(ctx_, basis, "weights");
    weights = ctx_.read_values(weights_node);
  } else {
    knots = read_bspline_basis(basis, dim, most);
  }
  std::int64_t total = 1;
  for (const KnotVector& kv : knots) total *= kv.num_ctrl();  // <= most, checked as they were read
  if (gt->rational) {
    if (static_cast<std::int64_t>(weights.size()) != total)
      ctx_.fail(weights_node, fmt::format("{} weights for a basis of {} functions", weights.size(), total));
    for (std::size_t i = 0; i < weights.size(); ++i)
      if (!(weights[i] > 0))
        ctx_.fail(weights_node, fmt::format("weight {} is {}; weights must be > 0", i, weights[i]));
  }

  std::int64_t geo_dim = 0;
  if (coefs.attribute("geoDim")) {
    geo_dim = int_attribute(coefs, "geoDim", 1, 1000);
  } else if (!values.empty() && static_cast<std::int64_t>(values.size()) % total == 0) {
    geo_dim = static_cast<std::int64_t>(values.size()) / total;  // one point per basis function
  } else {
    ctx_.fail(coefs, fmt::format("<coefs> has no geoDim attribute and its {} numbers are not a whole number of "
                                 "points for {} basis functions",
                                 values.size(), total));
  }
  if (static_cast<std::int64_t>(values.size()) != total * geo_dim)
    ctx_.fail(coefs, fmt::format("<coefs> holds {} numbers; {} basis functions times geoDim {} need {}", values.size(),
                                 total, geo_dim, total * geo_dim));
  try {
    TensorSpline spline(std::move(knots), static_cast<int>(geo_dim), std::move(values), std::move(weights));
    if (const auto problem = io_detail::rational_numbers_problem(spline)) throw ModelError(*problem);
    return spline;
  } catch (const ModelError& e) {
    ctx_.fail(geometry, e.what());
  }
}

std::vector<KnotVector> GismoReader::read_bspline_basis(pugi::xml_node basis, int dim, std::int64_t most) const {
  const std::string_view type = basis.attribute("type").value();
  if (!is_bspline_basis(type))
    ctx_.fail(basis,
              fmt::format("expected a B-spline basis (BSplineBasis or TensorBSplineBasis<d>), found type '{}'", type));
  std::int64_t functions = 1;
  if (dim == 1) return {read_knot_vector(only_child(ctx_, basis, "KnotVector"), functions, most)};
  std::vector<KnotVector> knots;
  for (pugi::xml_node child : basis.children("Basis")) {
    if (std::string_view(child.attribute("type").value()) != "BSplineBasis")
      ctx_.fail(child, fmt::format("a tensor basis holds BSplineBasis children, found type '{}'",
                                   child.attribute("type").value()));
    if (static_cast<int>(knots.size()) == dim)
      ctx_.fail(child, fmt::format("a {}-variate tensor basis needs {} child <Basis> elements, found more", dim, dim));
    knots.push_back(read_knot_vector(only_child(ctx_, child, "KnotVector"), functions, most));
  }
  if (static_cast<int>(knots.size()) != dim)
    ctx_.fail(basis, fmt::format("a {}-variate tensor basis needs {} child <Basis> elements (one per direction), "
                                 "found {}",
                                 dim, dim, knots.size()));
  return knots;
}

KnotVector GismoReader::read_knot_vector(pugi::xml_node kv, std::int64_t& functions, std::int64_t most) const {
  const int degree = static_cast<int>(int_attribute(kv, "degree", 0, kMaxOrder - 1));
  // The basis so far times this vector's functions must stay within `most`.
  auto count = [&](std::int64_t n) {
    const auto next = product_within(functions, n, most);
    if (!next) {
      if (most < kMaxControlPoints)
        ctx_.fail(kv, fmt::format("the basis has at least {} x {} functions, but <coefs> holds only {} numbers (one "
                                  "per function and coordinate)",
                                  functions, n, most));
      ctx_.fail(kv, fmt::format("the basis has at least {} x {} functions, above the limit of {}", functions, n,
                                kMaxControlPoints));
    }
    functions = *next;
  };
  try {
    if (const pugi::xml_attribute mode = kv.attribute("mode")) {
      // mode="uniform" csize="n": clamped uniform knots on [0, 1] for n basis functions
      // (gsXml<gsKnotVector>::get_into).
      if (std::string_view(mode.value()) != "uniform")
        ctx_.unsupported(kv,
                         fmt::format("KnotVector mode '{}' is not supported (only mode=\"uniform\")", mode.value()));
      const std::int64_t csize = int_attribute(kv, "csize", 1, kMaxControlPoints);
      count(csize);
      return KnotVector::clamped_uniform(degree + 1, static_cast<int>(csize));
    }
    KnotVector knots(degree + 1, ctx_.read_values(kv));
    count(knots.num_ctrl());
    return knots;
  } catch (const ModelError& e) {
    ctx_.fail(kv, e.what());
  }
}

}  // namespace

Model read_gismo_xml(std::string_view text, const std::string& source, const std::atomic<bool>* stop) {
  GismoReader reader(text, source, stop);
  return reader.read();
}

}  // namespace trivox
