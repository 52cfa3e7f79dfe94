// `trivox build SPEC -o OUT`: builds a volume with a constructor (extrude, ruled, revolve,
// sweep, coons, shell) from a construction file and saves it as a model whose format the
// output's extension names: IRIT .itd, G+Smo .xml or GoTools .g2 (docs/CLI.md#build). Prints
// the construction report; a volume that folds is an error unless --allow-fold.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.h"
#include "commands.h"
#include "stop_signal.h"
#include "trivox/error.h"
#include "trivox/io/model.h"
#include "trivox/scene/construction.h"

namespace trivox::cli {
namespace {

struct BuildOptions {
  std::string spec;
  std::string output;
  std::string name = "VOLUME";
  bool allow_fold = false;
};

// Writes the text to a temporary file beside `target` and renames it over the target, so a
// failed run never leaves a half-written model.
void write_atomically(const std::filesystem::path& target, const std::string& text) {
  const std::filesystem::path tmp = target.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw IoError(fmt::format("cannot write {}", tmp.string()));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw IoError(fmt::format("cannot write {}: {}", target.string(), ec.message()));
  }
}

void run_build(const BuildOptions& o) {
  // Checked before the construction, which may take a while.
  const std::optional<ModelFormat> format = model_format_of(o.output);
  if (!format)
    throw UsageError(
        fmt::format("-o {}: the extension names the model format: .itd (IRIT), .xml (G+Smo) or .g2 "
                    "(GoTools)",
                    o.output));
  const Constructed c = read_construction(o.spec, stop_on_signals());
  const ConstructionReport& r = c.report;
  const ParamBox& d = c.volume.domain();
  const std::array<int, 3> orders = c.volume.orders();
  fmt::print("{}: {} volume, orders {} x {} x {}, control points {} x {} x {}, {}\n", o.spec, r.constructor, orders[0],
             orders[1], orders[2], c.volume.spline().num_ctrl(0), c.volume.spline().num_ctrl(1),
             c.volume.spline().num_ctrl(2),
             c.volume.spline().is_rational() ? "rational (NURBS)" : "polynomial (B-spline)");
  fmt::print("  domain u [{:.6g}, {:.6g}]  v [{:.6g}, {:.6g}]  w [{:.6g}, {:.6g}]\n", d.lo.x, d.hi.x, d.lo.y, d.hi.y,
             d.lo.z, d.hi.z);
  const int samples = r.jacobian.positive + r.jacobian.negative + r.jacobian.zero;
  fmt::print("  jacobian {} ({} samples: {} positive, {} negative, {} zero)\n", r.describe(), samples,
             r.jacobian.positive, r.jacobian.negative, r.jacobian.zero);
  if (!r.exact)
    fmt::print("  approximate construction: deviation from the ideal shape up to {:.3g} mm (sampled)\n",
               r.approximation_error_mm);
  if (r.folds()) {
    if (!o.allow_fold)
      throw ModelError(
          fmt::format("{}: the {} volume folds over itself ({}); nothing written (--allow-fold writes it "
                      "anyway)",
                      o.spec, r.constructor, r.describe()));
    std::fflush(stdout);
    fmt::print(stderr, "trivox: warning: the volume folds over itself: {}\n", r.describe());
  }
  Model m;
  m.source = o.output;
  m.patches.push_back(Patch{o.name, 0, 0, c.volume.spline()});
  std::ostringstream text;
  write_model(text, m, *format);
  throw_if_signalled("writing the model");  // the last moment before the file appears
  write_atomically(o.output, text.str());
  fmt::print("wrote {}\n", o.output);
}

}  // namespace

void add_build_command(CLI::App& app) {
  auto opts = std::make_shared<BuildOptions>();
  CLI::App* cmd = app.add_subcommand(
      "build",
      "Build a volume with a constructor (extrude, ruled, revolve, sweep, coons, shell) from a construction "
      "file (JSON, as a scene cell's \"geometry\") and save it as a model: IRIT .itd, G+Smo .xml or GoTools .g2, "
      "by the output's extension.");
  cmd->add_option("spec", opts->spec, "construction file (JSON)")->required();
  cmd->add_option("-o,--output", opts->output, "the model file to write (.itd, .xml or .g2)")->required();
  cmd->add_option("--name", opts->name, "the object's name in the model file")->capture_default_str();
  cmd->add_flag("--allow-fold", opts->allow_fold, "write the volume even when it folds over itself");
  cmd->callback([opts] { run_build(*opts); });
}

}  // namespace trivox::cli
