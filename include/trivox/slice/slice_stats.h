// What slicing a layer counted: how its pixels were settled (the tracer's counters) and the
// columns of the paper's Table 2. A job sums its layers once (sum_layer_stats); stats.json
// (FORMATS.md), the program's summary and the Python module's stats dicts all take the values
// by walking one list (visit_layer_stats, and kTraceCounterFields inside it), so that a new
// counter reaches each of them, or fails to compile.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace trivox {

// How the candidate pixels of a layer were settled (SLICING.md, "how the tracer settles a
// pixel").
struct TraceCounters {
  std::int64_t candidates = 0;         // pixels inverted (inside the widened outlines)
  std::int64_t global_calls = 0;       // global solves
  std::int64_t global_unseeded = 0;    // of which for a pixel no solved neighbour could seed
  std::int64_t newton_evals = 0;       // evaluations of V (with or without J) by tracing and Newton
  std::int64_t guesses = 0;            // row guesses checked by one value-only evaluation
  std::int64_t guess_misses = 0;       // of which missed the residual tolerance
  std::int64_t jacobian_steps = 0;     // pixels evaluated with their Jacobian in a batch
  std::int64_t slow_path_pixels = 0;   // pixels settled by Newton from each neighbour, then the global solver
  std::int64_t folded_pixels = 0;      // pixels where a cell folds (several regular preimages)
  std::int64_t unresolved_pixels = 0;  // pixels where the global solver ran out of budget

  TraceCounters& operator+=(const TraceCounters& o) noexcept;
};

// The counters by their names in stats.json, in one list: summing, writing and reading them
// walk it, so a new counter is one member above and one row here.
struct TraceCounterField {
  std::string_view name;
  std::int64_t TraceCounters::*member;
};
inline constexpr std::array<TraceCounterField, 10> kTraceCounterFields = {{
    {"candidates", &TraceCounters::candidates},
    {"global_calls", &TraceCounters::global_calls},
    {"global_unseeded", &TraceCounters::global_unseeded},
    {"newton_evals", &TraceCounters::newton_evals},
    {"guesses", &TraceCounters::guesses},
    {"guess_misses", &TraceCounters::guess_misses},
    {"jacobian_steps", &TraceCounters::jacobian_steps},
    {"slow_path_pixels", &TraceCounters::slow_path_pixels},
    {"folded_pixels", &TraceCounters::folded_pixels},
    {"unresolved_pixels", &TraceCounters::unresolved_pixels},
}};

// A counter added above without its row here would be neither summed nor written.
static_assert(sizeof(TraceCounters) == kTraceCounterFields.size() * sizeof(std::int64_t),
              "every TraceCounters member needs its row in kTraceCounterFields");

inline TraceCounters& TraceCounters::operator+=(const TraceCounters& o) noexcept {
  for (const TraceCounterField& f : kTraceCounterFields) this->*f.member += o.*f.member;
  return *this;
}

// One layer (or, summed, a job): the columns of the paper's Table 2.
struct LayerStats : TraceCounters {
  int layer = 0;
  double z_mm = 0;
  double seconds = 0;                             // wall time of this layer (not part of the output bytes)
  double seconds_inverse = 0;                     // of which outlines and inversion
  double seconds_material = 0;                    // material evaluation
  double seconds_dither = 0;                      // dithering
  std::int64_t pixels_total = 0;                  // pixels in the bitmap
  std::int64_t pixels_inside = 0;                 // pixels inside some cell
  std::vector<std::int64_t> voxels_per_material;  // after dithering; index = scene material
  // Pixels each cell owns (index = scene cell): every inside pixel has exactly one owner,
  // so these add up to pixels_inside.
  std::vector<std::int64_t> pixels_per_cell;

  // Adds another layer's counters, times and per-material and per-cell counts (a shorter
  // vector counts as zeros); `layer` and `z_mm` stay.
  LayerStats& operator+=(const LayerStats& o);
};

inline LayerStats& LayerStats::operator+=(const LayerStats& o) {
  TraceCounters::operator+=(o);
  seconds += o.seconds;
  seconds_inverse += o.seconds_inverse;
  seconds_material += o.seconds_material;
  seconds_dither += o.seconds_dither;
  pixels_total += o.pixels_total;
  pixels_inside += o.pixels_inside;
  auto add = [](std::vector<std::int64_t>& to, const std::vector<std::int64_t>& from) {
    if (to.size() < from.size()) to.resize(from.size(), 0);
    for (std::size_t i = 0; i < from.size(); ++i) to[i] += from[i];
  };
  add(voxels_per_material, o.voxels_per_material);
  add(pixels_per_cell, o.pixels_per_cell);
  return *this;
}

// LayerStats member by member: a member added to LayerStats without one here (and in
// visit_layer_stats below) breaks this assertion.
namespace detail {
struct LayerStatsMembers {
  TraceCounters counters;
  int layer;
  double z_mm, seconds, seconds_inverse, seconds_material, seconds_dither;
  std::int64_t pixels_total, pixels_inside;
  std::vector<std::int64_t> voxels_per_material, pixels_per_cell;
};
}  // namespace detail
static_assert(sizeof(LayerStats) == sizeof(detail::LayerStatsMembers),
              "every LayerStats member needs its place in visit_layer_stats");

// The share of the inside voxels the global solver settled, in percent (0 when none is inside).
inline double global_share_percent(const LayerStats& s) noexcept {
  return s.pixels_inside > 0 ? 100.0 * static_cast<double>(s.global_calls) / static_cast<double>(s.pixels_inside) : 0.0;
}

// The layers of a job summed in their order, with a count per material and per cell even
// where no layer has one (num_materials, num_cells zeros to start from).
inline LayerStats sum_layer_stats(const std::vector<LayerStats>& layers, std::size_t num_materials,
                                  std::size_t num_cells) {
  LayerStats total;
  total.voxels_per_material.assign(num_materials, 0);
  total.pixels_per_cell.assign(num_cells, 0);
  for (const LayerStats& s : layers) total += s;
  return total;
}

// Which values visit_layer_stats names: a layer's own (its index, height and times) and the
// counts a sum of layers keeps too.
enum class LayerStatsPart { kLayer, kCounts };

// Calls visit(name, value) for every value of `s` under its name in stats.json: with kLayer,
// "layer", "z_mm" and the four times first; then the tracer's counters (kTraceCounterFields),
// "global_share_percent" (derived), "pixels_total", "pixels_inside", "voxels_per_material" and
// "pixels_per_cell". value is an int, a double, a std::int64_t or a std::vector<std::int64_t>.
template <class Visit>
void visit_layer_stats(const LayerStats& s, LayerStatsPart part, Visit&& visit) {
  if (part == LayerStatsPart::kLayer) {
    visit(std::string_view("layer"), s.layer);
    visit(std::string_view("z_mm"), s.z_mm);
    visit(std::string_view("seconds"), s.seconds);
    visit(std::string_view("seconds_inverse"), s.seconds_inverse);
    visit(std::string_view("seconds_material"), s.seconds_material);
    visit(std::string_view("seconds_dither"), s.seconds_dither);
  }
  for (const TraceCounterField& f : kTraceCounterFields) visit(f.name, s.*f.member);
  visit(std::string_view("global_share_percent"), global_share_percent(s));
  visit(std::string_view("pixels_total"), s.pixels_total);
  visit(std::string_view("pixels_inside"), s.pixels_inside);
  visit(std::string_view("voxels_per_material"), s.voxels_per_material);
  visit(std::string_view("pixels_per_cell"), s.pixels_per_cell);
}

}  // namespace trivox
