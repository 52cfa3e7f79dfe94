// G+Smo XML writer: each patch as a <Geometry> (BSpline, Nurbs, TensorBSpline2/3,
// TensorNurbs2/3) with id = its index, and, when every patch has the same number of
// parameters, a <MultiPatch> listing them with the interfaces and boundary sides that
// find_topology finds, as G+Smo's gsXml writes a gsMultiPatch (gsXmlUtils.cpp,
// appendBoxTopology: "patch side patch side dirMap dirOrientation" per interface, "patch
// side" per boundary side). The element layout follows what G+Smo writes and reads
// (gsTensorBSplineBasis, gsTensorNurbsBasis, gsKnotVector's XML): `degree` is the degree, the
// knots are listed in full, NURBS weights sit beside the inner B-spline basis, coefs are
// Euclidean points, one per row, u fastest.
//
// Numbers are written in the shortest form that reads back to the same double, so a model
// round-trips through read_gismo_xml exactly (weights and coordinates are stored apart, with
// no product to round).
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/topology.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {

namespace {

// A periodic direction is written as the unclamped basis it evaluates as: the knots as
// stored, and per basis function its (wrapped) control point.
std::vector<int> control_of_basis(const TensorSpline& s, int d) {
  std::vector<int> out;
  if (d >= s.param_dim()) return {0};
  const KnotVector& kv = s.knots(d);
  for (int i = 0; i < kv.num_basis(); ++i) out.push_back(kv.ctrl_index(i));
  return out;
}

void write_basis(std::string& buf, const TensorSpline& s, const char* indent) {
  auto out = std::back_inserter(buf);
  const int d = s.param_dim();
  auto knot_vector = [&](int dir, const std::string& pad) {
    const KnotVector& kv = s.knots(dir);
    fmt::format_to(out, "{}<KnotVector degree=\"{}\">", pad, kv.degree());
    const auto k = kv.knots();
    for (std::size_t i = 0; i < k.size(); ++i) fmt::format_to(out, "{}{}", i > 0 ? " " : "", k[i]);
    buf += "</KnotVector>\n";
  };
  if (d == 1) {
    fmt::format_to(out, "{}<Basis type=\"BSplineBasis\">\n", indent);
    knot_vector(0, std::string(indent) + " ");
    fmt::format_to(out, "{}</Basis>\n", indent);
    return;
  }
  fmt::format_to(out, "{}<Basis type=\"TensorBSplineBasis{}\">\n", indent, d);
  for (int dir = 0; dir < d; ++dir) {
    fmt::format_to(out, "{} <Basis type=\"BSplineBasis\" index=\"{}\">\n", indent, dir);
    knot_vector(dir, std::string(indent) + "  ");
    fmt::format_to(out, "{} </Basis>\n", indent);
  }
  fmt::format_to(out, "{}</Basis>\n", indent);
}

void write_geometry(std::string& buf, const TensorSpline& s, int id) {
  auto out = std::back_inserter(buf);
  const int d = s.param_dim();
  const bool rational = s.is_rational();
  const std::string type =
      d == 1 ? (rational ? "Nurbs" : "BSpline") : fmt::format("Tensor{}{}", rational ? "Nurbs" : "BSpline", d);
  fmt::format_to(out, " <Geometry type=\"{}\" id=\"{}\">\n", type, id);
  const std::vector<int> cu = control_of_basis(s, 0), cv = control_of_basis(s, 1), cw = control_of_basis(s, 2);
  if (rational) {
    fmt::format_to(out, "  <Basis type=\"{}\">\n", d == 1 ? "NurbsBasis" : fmt::format("TensorNurbsBasis{}", d));
    write_basis(buf, s, "   ");
    buf += "   <weights>\n";
    for (int k : cw)
      for (int j : cv)
        for (int i : cu) fmt::format_to(out, "{}\n", s.weight(i, j, k));
    buf += "   </weights>\n  </Basis>\n";
  } else {
    write_basis(buf, s, "  ");
  }
  fmt::format_to(out, "  <coefs geoDim=\"{}\">\n", s.point_dim());
  for (int k : cw)
    for (int j : cv)
      for (int i : cu) {
        const auto p = s.point(i, j, k);
        for (std::size_t c = 0; c < p.size(); ++c) fmt::format_to(out, "{}{}", c > 0 ? " " : "", p[c]);
        buf += '\n';
      }
  buf += "  </coefs>\n </Geometry>\n";
}

void write_multipatch(std::string& buf, const Model& model) {
  auto out = std::back_inserter(buf);
  const int n = static_cast<int>(model.patches.size());
  const int d = model.patches.front().spline.param_dim();
  const PatchTopology topo = find_topology(model);
  fmt::format_to(out, " <MultiPatch parDim=\"{}\" id=\"{}\">\n  <patches type=\"id_range\">0 {}</patches>\n", d, n,
                 n - 1);
  if (!topo.interfaces.empty()) {
    buf += "  <interfaces>\n";
    for (const PatchInterface& f : topo.interfaces) {
      fmt::format_to(out, "{} {} {} {}", f.first.patch, f.first.side, f.second.patch, f.second.side);
      for (int i = 0; i < d; ++i) fmt::format_to(out, " {}", f.dir_map[static_cast<std::size_t>(i)]);
      for (int i = 0; i < d; ++i) fmt::format_to(out, " {}", f.dir_orientation[static_cast<std::size_t>(i)] ? 1 : 0);
      buf += '\n';
    }
    buf += "  </interfaces>\n";
  }
  if (!topo.boundary.empty()) {
    buf += "  <boundary>\n";
    for (const PatchSide& s : topo.boundary) fmt::format_to(out, "{} {}\n", s.patch, s.side);
    buf += "  </boundary>\n";
  }
  buf += " </MultiPatch>\n";
}

}  // namespace

void write_gismo_xml(std::ostream& out, const Model& model) {
  std::string buf = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n";
  bool one_kind = !model.patches.empty();
  for (std::size_t i = 0; i < model.patches.size(); ++i) {
    const TensorSpline& s = model.patches[i].spline;
    one_kind = one_kind && s.param_dim() == model.patches.front().spline.param_dim();
    write_geometry(buf, s, static_cast<int>(i));
  }
  if (one_kind) write_multipatch(buf, model);
  buf += "</xml>\n";
  out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  out.flush();
  if (!out) throw IoError(fmt::format("writing G+Smo XML for '{}' failed", model.source));
}

}  // namespace trivox
