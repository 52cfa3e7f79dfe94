// `trivox probe MODEL`: the public way to check trivox against other spline systems. Reads
// points from standard input, one per line, and prints one JSON line per data line:
//  * default (inversion): model-space points x y z -> every preimage (u, v, w) in every
//    trivariate patch, or in --patch N only, found by the global solver;
//  * --eval --patch N: parameters (as many as the patch has directions) -> the point there.
// Numbers are printed with 17 significant digits so the output reads back exactly. The JSON
// format, the combined status over several patches and the exit codes are in docs/CLI.md.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_checks.h"
#include "cli_errors.h"
#include "commands.h"
#include "json_text.h"
#include "probe_input.h"
#include "stop_signal.h"
#include "trivox/error.h"
#include "trivox/inverse/invert.h"
#include "trivox/io/model.h"
#include "trivox/spline/volume.h"

namespace trivox::cli {
namespace {

struct ProbeOptions {
  std::string model_path;
  bool eval = false;
  std::optional<int> patch;
  GlobalSolveParams solve;
};

constexpr const char* kParamLists[] = {"u", "u v", "u v w"};  // by param_dim - 1

const Patch& selected_patch(const Model& model, int index) {
  const std::size_t n = model.patches.size();
  if (n == 0) throw UsageError(fmt::format("--patch {}: {} has no patches", index, model.source));
  if (index >= static_cast<int>(n))
    throw UsageError(
        fmt::format("--patch {}: {} has {} patch{} (0 to {})", index, model.source, n, n == 1 ? "" : "es", n - 1));
  return model.patches[static_cast<std::size_t>(index)];
}

bool is_geometry_trivariate(const TensorSpline& s) { return s.param_dim() == 3 && s.point_dim() == 3; }

// Reads standard input line by line and hands each well-formed data line to `handle`, which
// returns the JSON fields after "line" and "input". A malformed line gets an error line; the
// first one is reported as an InputError once the whole input has been answered, so a batch
// is never cut short by one bad line.
template <class Handle>
void answer_lines(std::size_t expected, std::string_view names, Handle handle) {
  std::string text;
  int line_number = 0, malformed = 0, first_malformed = 0;
  stop_on_signals();
  while (std::getline(std::cin, text)) {
    ++line_number;
    throw_if_signalled("answering the input");
    const ProbeLine line = parse_probe_line(text, expected, names);
    if (!line.has_data) continue;
    if (!line.error.empty()) {
      if (malformed++ == 0) first_malformed = line_number;
      fmt::print("{{\"line\":{},\"status\":\"error\",\"error\":{}}}\n", line_number, json_string(line.error));
      continue;
    }
    fmt::print("{{\"line\":{},\"input\":{},{}}}\n", line_number, json_numbers(line.values), handle(line.values));
  }
  throw_if_signalled("reading the input");  // a signal also ends the read of standard input
  if (std::cin.bad()) throw IoError("cannot read standard input");
  if (malformed > 0)
    throw InputError("<stdin>", first_malformed, "",
                     fmt::format("{} malformed input line{} (each has an error line in the output)", malformed,
                                 malformed == 1 ? "" : "s"));
}

void run_eval(const Model& model, int patch_index) {
  const TensorSpline& s = selected_patch(model, patch_index).spline;
  const auto dims = static_cast<std::size_t>(s.param_dim());
  std::vector<double> value(static_cast<std::size_t>(s.point_dim()));
  answer_lines(dims, kParamLists[dims - 1], [&](const std::vector<double>& t) {
    // TensorSpline::evaluate clamps to the domain; a parameter outside it is answered, not
    // silently moved.
    for (std::size_t d = 0; d < dims; ++d)
      if (!(t[d] >= s.lo(static_cast<int>(d)) && t[d] <= s.hi(static_cast<int>(d))))
        return fmt::format("\"patch\":{},\"status\":\"outside\"", patch_index);
    s.evaluate(t, value);
    return fmt::format("\"patch\":{},\"status\":\"ok\",\"position\":{}", patch_index, json_numbers(value));
  });
}

struct PatchSolver {
  int patch = 0;
  GlobalSolver solver;
};

// Combines the per-patch outcomes into one status (docs/CLI.md): incomplete if any patch's
// search ran out of boxes; none if no patch has a preimage; the patch's own status when
// exactly one patch has preimages; multiple when several patches do (x on a shared face).
GlobalStatus combined_status(const std::vector<GlobalResult>& results) {
  int with_preimages = 0;
  GlobalStatus single = GlobalStatus::kNone;
  for (const GlobalResult& r : results) {
    if (r.status == GlobalStatus::kIncomplete) return GlobalStatus::kIncomplete;
    if (!r.preimages.empty()) {
      ++with_preimages;
      single = r.status;
    }
  }
  if (with_preimages == 0) return GlobalStatus::kNone;
  return with_preimages == 1 ? single : GlobalStatus::kMultiple;
}

void run_invert(const Model& model, std::optional<int> only_patch, const GlobalSolveParams& params) {
  std::vector<int> indices;
  if (only_patch) {
    const TensorSpline& s = selected_patch(model, *only_patch).spline;
    if (!is_geometry_trivariate(s))
      throw UsageError(
          fmt::format("--patch {} has {} parameter(s) and {} coordinate(s) per point; inverting "
                      "needs a trivariate with 3D points (use --eval to evaluate it)",
                      *only_patch, s.param_dim(), s.point_dim()));
    indices.push_back(*only_patch);
  } else {
    for (int i : model.volume_indices())
      if (is_geometry_trivariate(model.patches[static_cast<std::size_t>(i)].spline)) indices.push_back(i);
    if (indices.empty())
      throw UsageError(
          fmt::format("{} has no trivariate with 3D points to invert in (use --eval --patch N "
                      "to evaluate its patches)",
                      model.source));
  }

  // The solvers keep pointers to the volumes: build all volumes first, then the solvers.
  std::vector<Volume> volumes;
  volumes.reserve(indices.size());
  for (int i : indices) volumes.emplace_back(model.patches[static_cast<std::size_t>(i)].spline);
  std::vector<PatchSolver> solvers;
  solvers.reserve(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) solvers.push_back({indices[k], GlobalSolver(volumes[k])});

  std::vector<GlobalResult> results(solvers.size());
  answer_lines(3, "x y z", [&](const std::vector<double>& xyz) {
    const Vec3 x{xyz[0], xyz[1], xyz[2]};
    for (std::size_t k = 0; k < solvers.size(); ++k) results[k] = solvers[k].solver.solve(x, params);
    std::string preimages;
    for (std::size_t k = 0; k < solvers.size(); ++k)
      for (const Preimage& p : results[k].preimages) {
        const double uvw[3] = {p.uvw.x, p.uvw.y, p.uvw.z};
        preimages +=
            fmt::format("{}{{\"patch\":{},\"uvw\":{},\"residual\":{},\"det\":{}}}", preimages.empty() ? "" : ",",
                        solvers[k].patch, json_numbers(uvw), json_number(p.residual), json_number(p.det));
      }
    return fmt::format("\"status\":\"{}\",\"preimages\":[{}]", to_string(combined_status(results)), preimages);
  });
}

void run_probe(const ProbeOptions& options) {
  const Model model = read_model(options.model_path, stop_on_signals());
  GlobalSolveParams solve = options.solve;
  solve.stop = stop_on_signals();  // a global solve of a big volume may take seconds
  if (options.eval)
    run_eval(model, *options.patch);
  else
    run_invert(model, options.patch, solve);
}

}  // namespace

void add_probe_command(CLI::App& app) {
  auto options = std::make_shared<ProbeOptions>();
  CLI::App* cmd =
      app.add_subcommand("probe",
                         "Read points from standard input, one per line: invert model-space points x y z (default) or "
                         "evaluate parameters (--eval --patch N); print one JSON line per point.");
  cmd->add_option("model", options->model_path, "Model file: IRIT .itd, G+Smo .xml or GoTools .g2")->required();
  CLI::Option* patch = cmd->add_option("--patch", options->patch,
                                       "Patch index (from `trivox info`): the patch to evaluate, or the only "
                                       "trivariate to invert in")
                           ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--eval", options->eval, "Evaluate parameters (one per patch direction) instead of inverting")
      ->needs(patch);
  cmd->add_option("--tolerance", options->solve.newton.residual_tolerance_model,
                  "Inversion: largest |V(u,v,w) - x| accepted as a solution, in model units")
      ->check(positive_number())
      ->capture_default_str();
  cmd->callback([options] { run_probe(*options); });
}

}  // namespace trivox::cli
