#include "job_options.h"

#include <algorithm>
#include <array>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_checks.h"
#include "cli_errors.h"
#include "trivox/error.h"
#include "trivox/limits.h"
#include "trivox/output/display_colours.h"
#include "trivox/output/layer_writer.h"

namespace trivox::cli {

namespace {

// "a:b" (1-based, inclusive, as in the file names; either end may be left out).
void parse_layers(const std::string& text, JobParams& p) {
  if (text.empty()) return;
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw UsageError(fmt::format("--layers takes FIRST:LAST (1-based), got '{}'", text));
  try {
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    if (!a.empty()) p.first_layer = std::stoi(a) - 1;
    if (!b.empty()) p.last_layer = std::stoi(b) - 1;
  } catch (const std::exception&) {
    throw UsageError(fmt::format("--layers takes FIRST:LAST (1-based), got '{}'", text));
  }
  if (p.first_layer < 0 || (p.last_layer >= 0 && p.last_layer < p.first_layer))
    throw UsageError(fmt::format("--layers {}: layers count from 1 and FIRST must not exceed LAST", text));
}

// "I/N" with 1 <= I <= N.
void parse_shard(const std::string& text, JobParams& p) {
  if (text.empty()) return;
  const auto slash = text.find('/');
  bool ok = slash != std::string::npos;
  if (ok) {
    try {
      std::size_t used_i = 0, used_n = 0;
      p.shard_index = std::stoi(text.substr(0, slash), &used_i);
      p.shard_count = std::stoi(text.substr(slash + 1), &used_n);
      ok = used_i == slash && used_n == text.size() - slash - 1;
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok || p.shard_count < 1 || p.shard_index < 1 || p.shard_index > p.shard_count)
    throw UsageError(fmt::format("--shard takes I/N with 1 <= I <= N (e.g. 2/4), got '{}'", text));
}

}  // namespace

void add_job_options(CLI::App& cmd, JobOptions& o, bool output_required) {
  cmd.add_option("scene", o.scene, "Scene file (JSON, docs/SCENE.md)")->required();
  // validate checks the folder as slice would, creating nothing (output_folder_problem).
  auto* out = cmd.add_option("-o,--output", o.output,
                             output_required ? "Output folder (created if missing)"
                                             : "Output folder to check as slice would (nothing is created)");
  if (output_required) out->required();
  cmd.add_option("-j,--threads", o.threads, "Worker threads (default: all cores)")->check(thread_count());
  cmd.add_option("--layers", o.layers, "Only layers FIRST:LAST (1-based, inclusive)");
  cmd.add_option("--tracing", o.tracing,
                 "Seeding of the inverse: none, previous-point, previous-line, full (the paper's), predict, flood")
      ->capture_default_str();
  cmd.add_option("--residual-tolerance", o.residual_tolerance_mm,
                 "Largest |V(u,v,w) - pixel centre| of an inside pixel's solution, mm")
      ->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--outline-tolerance", o.outline_tolerance_mm,
                 "Largest distance between a cell's boundary and its triangulated outline, mm: the band of pixels "
                 "decided by the exact inverse is twice as wide (default: an eighth of the finest pitch)")
      ->check(positive_number());
  cmd.add_option("--dither", o.dither,
                 "Dithering: floyd-steinberg, jarvis-judice-ninke, stucki, blue-noise (default: the scene's, else "
                 "floyd-steinberg)");
  cmd.add_option("--skin", o.skin_voxels, "Outer voxels of each layer that take the nearest pure material, undithered");
  cmd.add_option("--vary-by-layer", o.vary_by_layer,
                 "Change the dithering pattern with the layer index: true or false (default: the scene's, else true)");
  cmd.add_option("--format", o.formats,
                 "Outputs: voxelprint (RGBA PNG stack), bitmaps (1-bit PNG per material), legacy (1-bit BMPs), tiff "
                 "(multi-page TIFF), vdb (OpenVDB grid per material), gcvf (GrabCAD Voxel Print package), greyscale "
                 "(8-bit PNG stack for resin printers), sl1, sl1s (Prusa SL1/SL1S archive), preview (contact sheet and "
                 "cuts)")
      ->delimiter(',')
      ->check(CLI::IsMember(layer_writer_names()))
      ->capture_default_str();
  cmd.add_option("--prefix", o.prefix, "File-name prefix of the layer images")->capture_default_str();
  cmd.add_option("--background", o.background,
                 "Background colour R,G,B (opaque; R,G,B,255 too) of the printer images (default: black, or the "
                 "first free of white and the greys when a material is black)")
      ->delimiter(',');
  cmd.add_option("--gcvf-names", o.gcvf_names,
                 "Material names in the gcvf package's ConfigFile.xml: codes (the Stratasys codes where known, "
                 "e.g. VeroCY-V) or scene (as the scene names them)")
      ->check(CLI::IsMember({"codes", "scene"}))
      ->capture_default_str();
  cmd.add_flag("--gcvf-all-materials", o.gcvf_all_materials,
               "List every material in the gcvf package, also those with no voxel (default: left out)");
  cmd.add_option("--gcvf-extras", o.gcvf_extras,
                 "Extra members of the gcvf package: stl (model.stl, the cells' boundary), bbox (bounding_box.txt)")
      ->delimiter(',')
      ->check(CLI::IsMember({"stl", "bbox"}));
  cmd.add_option("--min-layers", o.min_layers,
                 "Pad with empty layers up to this count (default: 30 when a format GrabCAD Voxel Print reads, "
                 "voxelprint or gcvf, is written, as it needs; 0 otherwise; fewer is reported)")
      ->check(CLI::Range(0, JobParams::kMaxMinLayers));
  cmd.add_option("--preview", o.preview_layers,
                 "Also write these layers (1-based, comma-separated) as preview/layer_NNNNN.png in display colours "
                 "with square pixels")
      ->delimiter(',');
  cmd.add_option("--shard", o.shard,
                 "Slice only shard I of N (I/N, layers dealt round-robin); merge with `trivox merge`");
  cmd.add_option("--memory-limit", o.memory_limit_mb,
                 "Refuse a job whose estimated peak memory exceeds this many MB (default: the machine's memory)")
      ->check(positive_number());
  cmd.add_flag("--allow-empty", o.allow_empty,
               "Accept a stack without the object (a bitmap under 2 pixels along x or y, or no voxel inside): "
               "otherwise exit 6");
  cmd.add_flag("--no-checks", o.no_checks,
               "Do not refuse a job that the estimates say will not fit the disk or the memory limit");
}

SliceParams slice_params_of(const JobOptions& o, const Scene& scene) {
  SliceParams params;
  const auto strategy = parse_tracing_strategy(o.tracing);
  if (!strategy)
    throw UsageError(fmt::format(
        "--tracing must be none, previous-point, previous-line, full, predict or flood, got '{}'", o.tracing));
  params.tracing = *strategy;
  params.newton.residual_tolerance_model = o.residual_tolerance_mm;
  params.outline_tolerance_mm = o.outline_tolerance_mm;
  // Dithering: the scene's settings, with the options given here on top.
  DitherParams dither = scene.dithering.value_or(DitherParams{});
  if (!o.dither.empty() && !set_dither_method(o.dither, dither))
    throw UsageError(
        fmt::format("--dither must be one of {}, got '{}'", fmt::join(dither_method_names(), ", "), o.dither));
  if (o.skin_voxels) {
    if (*o.skin_voxels < 0 || *o.skin_voxels > DitherParams::kMaxSkinVoxels)
      throw UsageError(
          fmt::format("--skin takes 0 to {} voxels, got {}", DitherParams::kMaxSkinVoxels, *o.skin_voxels));
    dither.skin_voxels = *o.skin_voxels;
  }
  if (o.vary_by_layer) dither.vary_by_layer = *o.vary_by_layer;
  params.dither = dither;
  return params;
}

JobParams job_params_of(const JobOptions& o) {
  JobParams job;
  job.output_dir = o.output;
  // The one way the memory limit enters: the estimate, its checks and the slicer's outlines
  // (slice_params_for) take it from here.
  if (!o.no_checks) job.memory_limit_bytes = memory_limit_of(o);
  job.threads = o.threads;
  job.formats = o.formats;
  // Before anything is read: a prefix that is a path would write outside -o (exit 3).
  if (const auto problem = file_name_part_problem(o.prefix))
    throw Error(fmt::format("--prefix {}: the prefix becomes part of every layer file's name: {}", shown_name(o.prefix),
                            *problem));
  job.prefix = o.prefix;
  job.min_layers = o.min_layers;
  if (!o.background.empty()) {
    if (o.background.size() != 3 && o.background.size() != 4)
      throw UsageError("--background takes three numbers R,G,B (or R,G,B,255)");
    std::array<std::uint8_t, 4> rgba{0, 0, 0, 255};
    for (std::size_t i = 0; i < o.background.size(); ++i) {
      if (o.background[i] < 0 || o.background[i] > 255) throw UsageError("--background values are 0..255");
      rgba[i] = static_cast<std::uint8_t>(o.background[i]);
    }
    if (rgba[3] != 255) throw UsageError("--background: printer images are opaque, so its alpha must be 255");
    job.background_rgba = rgba;
  }
  job.gcvf.material_codes = o.gcvf_names == "codes";
  job.gcvf.omit_unused = !o.gcvf_all_materials;
  for (const std::string& extra : o.gcvf_extras) {
    if (extra == "stl") job.gcvf.mesh_stl = true;
    if (extra == "bbox") job.gcvf.bounding_box = true;
  }
  parse_layers(o.layers, job);
  for (int layer : o.preview_layers) {
    if (layer < 1) throw UsageError(fmt::format("--preview takes layer numbers from 1, got {}", layer));
    job.preview_layers.push_back(layer - 1);
  }
  parse_shard(o.shard, job);
  return job;
}

void warn_about_printer(const Scene& scene) {
  if (const auto warning = layer_thickness_warning(scene.printer))
    fmt::print(stderr, "trivox: warning: {}\n", *warning);
}

std::optional<std::uint64_t> memory_limit_of(const JobOptions& o) { return memory_limit_from_mb(o.memory_limit_mb); }

void print_estimate(const JobEstimate& e) {
  fmt::print("  layers: {} ({} of the model, {} empty padding layers)\n", e.job_layers, e.model_layers,
             e.padded_layers);
  fmt::print("  bitmap: {} x {} px, {} voxels in all\n", e.width_px, e.height_px, e.pixels);
  if (e.sampled_layers > 0) {
    // The layer files, the whole-job files, stats.json and the manifest.
    fmt::print("  output: about {} in {} files (from {} sample layers)\n", byte_text(e.output_bytes),
               static_cast<std::int64_t>(e.files_per_layer) * e.job_layers + e.whole_job_files + 2, e.sampled_layers);
    if (e.scratch_bytes > 0)
      fmt::print("  spool files: about {} more while the job runs (removed when it completes)\n",
                 byte_text(e.scratch_bytes));
    fmt::print("  time: about {:.0f} s with {} (sample layers sliced one at a time on this machine now)\n", e.seconds,
               thread_text(e.threads));
  }
  fmt::print("  peak memory: about {} with {}{}\n", byte_text(e.peak_memory_bytes), thread_text(e.threads),
             e.stack_memory_bytes > 0
                 ? fmt::format(" ({} of it for the stack outputs)", byte_text(e.stack_memory_bytes))
                 : std::string());
}

std::vector<std::string> colour_warnings(const Scene& scene, const std::array<std::uint8_t, 4>& background) {
  std::vector<Rgba> rgba;
  for (const MaterialDef& m : scene.materials) rgba.push_back(m.rgba);
  const std::vector<Rgb> shown = display_colours(rgba, background);
  std::vector<std::string> lines;
  // The previews' background is chosen apart from every material; one given with --background
  // (or, with many materials, the best there is) may not be.
  const Rgb back{background[0], background[1], background[2]};
  for (std::size_t j = 0; j < rgba.size(); ++j) {
    const Rgb own{rgba[j][0], rgba[j][1], rgba[j][2]};
    const double d = colour_difference(own, back);
    if (d >= kDistinctColourDifference) continue;
    const Rgb& c = shown[j];
    lines.push_back(fmt::format(
        "material '{}' (#{:02X}{:02X}{:02X}) has nearly the previews' background colour #{:02X}{:02X}{:02X} "
        "(difference {:.1f}, below {:g}), so previews show it as #{:02X}{:02X}{:02X}; choose another "
        "--background or give the material a colour of its own (\"rgba\") to see it as it is",
        scene.materials[j].name, own[0], own[1], own[2], back[0], back[1], back[2], d, kDistinctColourDifference, c[0],
        c[1], c[2]));
  }
  for (const SimilarColours& pair : similar_colours(rgba)) {
    const MaterialDef& a = scene.materials[static_cast<std::size_t>(pair.first)];
    const MaterialDef& b = scene.materials[static_cast<std::size_t>(pair.second)];
    const Rgb& c = shown[static_cast<std::size_t>(pair.second)];
    lines.push_back(fmt::format(
        "materials '{}' and '{}' have nearly the same colour (difference {:.1f}, below {:g}): the layer images "
        "keep both exact colours, but a person cannot tell them apart, so previews show '{}' as #{:02X}{:02X}{:02X}; "
        "give one of them a colour of its own (\"rgba\") to see them apart everywhere",
        a.name, b.name, pair.difference, kDistinctColourDifference, b.name, c[0], c[1], c[2]));
  }
  return lines;
}

}  // namespace trivox::cli
