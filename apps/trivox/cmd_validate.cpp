// `trivox validate SCENE [job options]`: checks a scene and a job before it runs and
// estimates what it will cost (docs/CLI.md#validate).
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "stop_signal.h"
#include "trivox/error.h"
#include "trivox/job/job_estimate.h"
#include "trivox/job/job_lock.h"
#include "trivox/job/slice_job.h"
#include "trivox/scene/fraction_sums.h"
#include "trivox/scene/scene.h"

namespace trivox::cli {

namespace {

struct ValidateOptions {
  JobOptions job;
  int samples = 3;
};

void run_validate(const ValidateOptions& v) {
  const JobOptions& o = v.job;
  JobParams job = job_params_of(o);
  job.stop = stop_on_signals();  // the scene's constructions and the sample layers read it
  // The folder `trivox slice` would refuse, refused here too (without creating it).
  if (!o.output.empty())
    if (auto problem = output_folder_problem(job.output_dir)) throw IoError(std::move(*problem));
  const Scene scene = read_scene(o.scene, job.stop);
  warn_about_printer(scene);
  const Slicer slicer(scene, slice_params_for(slice_params_of(o, scene), job));
  check_bitmap_shows_object(slicer, o.scene, o.allow_empty);
  const JobEstimate e = estimate_job(slicer, job, EstimateParams{v.samples});
  fmt::print("{}: {} cells, {} materials, printer {}\n", o.scene, scene.cells.size(), scene.num_materials(),
             scene.printer.name);
  print_estimate(e);
  for (const std::string& w : colour_warnings(scene, job_preview_background(scene, job)))
    fmt::print("  warning: {}\n", w);
  if (!o.output.empty()) {
    if (const auto free = free_disk_bytes(job.output_dir))
      fmt::print("  free disk at {}: {}\n", o.output, byte_text(*free));
  }
  if (const auto limit = memory_limit_of(o)) fmt::print("  memory limit: {}\n", byte_text(*limit));
  if (!o.no_checks) check_job_fits(e, job);
  // The fraction rules, proved cell by cell over each cell's domain (or not).
  throw_if_signalled("estimating the job");
  const std::vector<CellFractionCheck> checks = check_scene_fractions(scene);
  int proved = 0, unproved = 0;
  for (const CellFractionCheck& c : checks) {
    const Cell& cell = scene.cells[static_cast<std::size_t>(c.cell)];
    const FractionCheck& f = c.check;
    if (f.outcome == FractionCheckOutcome::kProved) {
      ++proved;
    } else if (f.outcome == FractionCheckOutcome::kUnproved) {
      ++unproved;
      fmt::print(
          "  fraction sums: cell '{}' ({}/material): cannot prove: {} in u [{:.6g}, {:.6g}] v [{:.6g}, {:.6g}] "
          "w [{:.6g}, {:.6g}]\n",
          cell.name, cell.pointer, f.reason, f.box.lo.x, f.box.hi.x, f.box.lo.y, f.box.hi.y, f.box.lo.z, f.box.hi.z);
    } else {
      throw InputError(
          scene.source, 0, cell.pointer + "/material",
          fmt::format("cell '{}': {} at (u,v,w) = ({:.6g}, {:.6g}, {:.6g}), (x,y,z) = ({:.6g}, {:.6g}, {:.6g}) mm: "
                      "slicing stops with an error at the first voxel there; correct the material, or set "
                      "\"fraction_sums\" to \"normalise\" to scale such sums down",
                      cell.name, f.rule, f.uvw.x, f.uvw.y, f.uvw.z, f.xyz.x, f.xyz.y, f.xyz.z));
    }
  }
  // The greyscale source's values, proved finite (a NaN would stop the job at its first pixel).
  int grey_unproved = 0;
  for (const CellFractionCheck& c : check_scene_grey_sources(scene)) {
    const Cell& cell = scene.cells[static_cast<std::size_t>(c.cell)];
    const FractionCheck& f = c.check;
    if (f.outcome == FractionCheckOutcome::kBroken)
      throw InputError(
          scene.source, 0, "/greyscale/source",
          fmt::format("cell '{}': the greyscale source is not a finite number at (u,v,w) = ({:.6g}, {:.6g}, {:.6g}), "
                      "(x,y,z) = ({:.6g}, {:.6g}, {:.6g}) mm: slicing stops with an error at the first pixel there",
                      cell.name, f.uvw.x, f.uvw.y, f.uvw.z, f.xyz.x, f.xyz.y, f.xyz.z));
    if (f.outcome == FractionCheckOutcome::kUnproved) {
      ++grey_unproved;
      fmt::print(
          "  greyscale source: cell '{}': cannot prove its values finite in u [{:.6g}, {:.6g}] v [{:.6g}, "
          "{:.6g}] w [{:.6g}, {:.6g}]\n",
          cell.name, f.box.lo.x, f.box.hi.x, f.box.lo.y, f.box.hi.y, f.box.lo.z, f.box.hi.z);
    }
  }
  fmt::print("  fraction sums: {} of {} cells proved within the scene's policy ({})\n", proved, checks.size(),
             scene.fraction_policy.policy == SumPolicy::kError
                 ? fmt::format("\"error\", tolerance {}", scene.fraction_policy.tolerance)
                 : std::string("\"normalise\": only finite values to prove"));
  if (unproved > 0 || grey_unproved > 0) {
    const auto cells = [](int n) { return fmt::format("{} cell{}", n, n == 1 ? "" : "s"); };
    const std::string what = unproved > 0 && grey_unproved > 0
                                 ? fmt::format("the fraction sums of {} and the greyscale source of {}",
                                               cells(unproved), cells(grey_unproved))
                             : unproved > 0 ? fmt::format("the fraction sums of {}", cells(unproved))
                                            : fmt::format("the greyscale source of {}", cells(grey_unproved));
    fmt::print("cannot prove: {} (above); the job can run, but stops at the first voxel where they break the rule\n",
               what);
    return;
  }
  fmt::print("ok: the job can run\n");
}

}  // namespace

void add_validate_command(CLI::App& app) {
  auto v = std::make_shared<ValidateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check a scene and a slicing job without running it; estimate layers, size, memory and time");
  add_job_options(*cmd, v->job, false);
  cmd->add_option("--samples", v->samples, "Layers to slice for the size and time estimates")
      ->check(CLI::Range(0, 50))
      ->capture_default_str();
  cmd->callback([v] { run_validate(*v); });
}

void print_scene_info(const std::string& scene_path) {
  JobOptions o;
  o.scene = scene_path;
  const Scene scene = read_scene(o.scene);
  // The estimate of a job with the default options, sampled whatever the memory limit.
  JobParams job = job_params_of(o);
  const Slicer slicer(scene, slice_params_for(slice_params_of(o, scene), job));
  job.memory_limit_bytes.reset();
  const SliceLayout& L = slicer.layout();
  fmt::print("{}: scene, {} cells, {} materials, printer {}\n", scene_path, scene.cells.size(), scene.num_materials(),
             scene.printer.name);
  for (const MaterialDef& m : scene.materials)
    fmt::print("  material {}: rgba {},{},{},{}\n", m.name, m.rgba[0], m.rgba[1], m.rgba[2], m.rgba[3]);
  fmt::print("  pixels {:.4f} x {:.4f} mm, layers {:.4f} mm\n", L.pitch_x_mm, L.pitch_y_mm, L.layer_mm);
  for (const std::string& w : colour_warnings(scene, job_preview_background(scene, job)))
    fmt::print("  warning: {}\n", w);
  fmt::print("estimate for `trivox slice` with the default options:\n");
  print_estimate(estimate_job(slicer, job));
}

}  // namespace trivox::cli
