// IRIT text (.itd) writer: one [OBJECT name [CURVE|SURFACE|TRIVAR BSPLINE ...]] per patch.
// Every patch is written as a B-spline (a Bezier patch is one without interior knots), with
// [KVP for periodic directions and P<d> points (weight first, coordinates multiplied by the
// weight, as IRIT stores them) for rational patches.
//
// Numbers are printed with 17 significant digits, which identifies every double uniquely:
// knots, weights and polynomial coordinates read back bit for bit. A rational coordinate is
// stored as the product w*x, and reading divides by w again, which may move x by an ulp.
#include <array>
#include <iterator>
#include <ostream>
#include <string>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {

namespace {

constexpr int kMaxItdPointDim = 9;  // IRIT point types stop at E9/P9

// Object names are single IRIT words: blanks, brackets and quotes would end them early.
std::string itd_name(const std::string& name, std::size_t index) {
  std::string out;
  for (char c : name) {
    const bool breaks_word = c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || c == '[' ||
                             c == ']' || c == '"' || static_cast<unsigned char>(c) < 0x20;
    out.push_back(breaks_word ? '_' : c);
  }
  return out.empty() ? fmt::format("PATCH_{}", index) : out;
}

void write_patch(std::string& buf, const Patch& patch, std::size_t index) {
  constexpr std::array<const char*, 4> kKeyword = {"", "CURVE", "SURFACE", "TRIVAR"};
  const TensorSpline& s = patch.spline;
  const int dims = s.param_dim();
  auto out = std::back_inserter(buf);

  fmt::format_to(out, "[OBJECT {}\n    [{} BSPLINE", itd_name(patch.name, index),
                 kKeyword[static_cast<std::size_t>(dims)]);
  for (int d = 0; d < dims; ++d) fmt::format_to(out, " {}", s.num_ctrl(d));
  for (int d = 0; d < dims; ++d) fmt::format_to(out, " {}", s.knots(d).order());
  fmt::format_to(out, " {}{}\n", s.is_rational() ? 'P' : 'E', s.point_dim());

  for (int d = 0; d < dims; ++d) {
    const KnotVector& kv = s.knots(d);
    fmt::format_to(out, "\t[{}", kv.is_periodic() ? "KVP" : "KV");
    for (double k : kv.knots()) fmt::format_to(out, " {:.17g}", k);
    buf += "]\n";
  }

  const int n = s.total_ctrl();
  const int first_break = s.num_ctrl(0);                   // blank line between rows
  const int second_break = s.num_ctrl(0) * s.num_ctrl(1);  // and another between layers
  for (int i = 0; i < n; ++i) {
    if (i > 0 && i % first_break == 0) buf += '\n';
    if (i > 0 && i % second_break == 0) buf += '\n';
    const auto p = s.points().subspan(static_cast<std::size_t>(i) * static_cast<std::size_t>(s.point_dim()),
                                      static_cast<std::size_t>(s.point_dim()));
    buf += "\t[";
    if (s.is_rational()) {
      const double w = s.weights()[static_cast<std::size_t>(i)];
      fmt::format_to(out, "{:.17g}", w);
      for (double x : p) fmt::format_to(out, " {:.17g}", w * x);
    } else {
      for (std::size_t c = 0; c < p.size(); ++c) fmt::format_to(out, "{}{:.17g}", c > 0 ? " " : "", p[c]);
    }
    buf += "]\n";
  }
  buf += "    ]\n]\n";
}

}  // namespace

void write_itd(std::ostream& out, const Model& model) {
  // Check every patch first so a model IRIT cannot hold leaves no half-written file.
  for (const Patch& p : model.patches)
    if (p.spline.point_dim() > kMaxItdPointDim)
      throw ModelError(fmt::format("patch '{}' has {} coordinates per point; IRIT stores 1 to {} (E1..E9, P1..P9)",
                                   p.name, p.spline.point_dim(), kMaxItdPointDim));

  std::string buf;
  for (std::size_t i = 0; i < model.patches.size(); ++i) {
    buf.clear();
    write_patch(buf, model.patches[i], i);
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (!out) throw IoError(fmt::format("writing IRIT text for '{}' failed", model.source));
  }
  out.flush();
  if (!out) throw IoError(fmt::format("writing IRIT text for '{}' failed", model.source));
}

}  // namespace trivox
