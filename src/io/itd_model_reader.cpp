// The MODEL objects of an IRIT .itd file: trimmed surfaces, their loops and the trimming
// segments between them (Model::trimmed_models; see itd_reader.cpp).
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/itd_parser.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/limits.h"

namespace trivox::itd {

// [MODEL n_surfaces n_segments [MDLTSRF ...]* [MDLTSEG ...]* ]; segment and surface
// references are 1-based in the file, 0-based once read.
void ItdParser::parse_model(const Token& open) {
  const std::string where = fmt::format("MODEL in object '{}'", object_name());
  TrimmedModel model;
  model.name = object_name();
  model.source_line = open.line;
  const int num_surfaces = read_int(where, "number of trimmed surfaces", 0, 10'000'000);
  const int num_segments = read_int(where, "number of trimming segments", 0, 10'000'000);
  while (const std::optional<Token> next = next_group(open, where, " in the MODEL")) {
    const Token& t = *next;
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
  while (const std::optional<Token> next = next_group(open, here, "")) {
    const Token& t = *next;
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
  while (const std::optional<Token> next = next_group(open, here, "")) {
    const Token& t = *next;
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

}  // namespace trivox::itd
