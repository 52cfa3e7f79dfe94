// `trivox init [--printer P] [--materials A,B] [--mesh FILE] NAME.json`: writes a scene to start
// from, a box graded between two library materials (or the part a mesh encloses, in the box
// around it) that slices as is (docs/CLI.md#init).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "stop_signal.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/output/atomic_file.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/scene/mesh_file_report.h"
#include "trivox/scene/scene.h"
#include "trivox/scene/starter_scene.h"

namespace trivox::cli {

namespace {

struct InitOptions {
  std::string path;
  StarterSceneParams scene;
  std::string mesh;  // --mesh: the file as given
  bool force = false;
};

// The mesh as the scene names it: relative to the scene's folder when it can be, else absolute.
std::string mesh_name_in_scene(const std::string& mesh, const std::string& scene_path) {
  std::error_code ec;
  const std::filesystem::path mesh_abs = std::filesystem::absolute(mesh, ec);
  const std::filesystem::path folder = std::filesystem::absolute(scene_path, ec).parent_path();
  std::filesystem::path relative = mesh_abs.lexically_normal().lexically_relative(folder.lexically_normal());
  return relative.empty() ? mesh_abs.lexically_normal().generic_string() : relative.generic_string();
}

void run_init(const InitOptions& o) {
  StarterSceneParams params = o.scene;
  std::optional<MeshFileReport> mesh;
  if (!o.mesh.empty()) {
    // Checked as the scene will check it, at the printer's finest pitch: a mesh the even-odd
    // rule cannot take is written with the winding-number rule, and said so.
    PrinterProfile printer;
    try {
      printer = builtin_printer_profile(params.printer);
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
    mesh = describe_mesh_file(o.mesh, printer.finest_pitch_mm(), stop_on_signals());
    params.mesh = mesh_name_in_scene(o.mesh, o.path);
    params.inside_rule = mesh->passed ? "even-odd" : "winding-number";
  }
  std::string text;
  try {
    text = starter_scene_text(params);
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    throw UsageError(e.what());  // a printer or material name the command line got wrong
  }
  std::error_code ec;
  if (!o.force && std::filesystem::exists(o.path, ec))
    throw IoError(fmt::format("{} exists already; choose another name, or --force to replace it", o.path));
  // Read back before writing: what init writes must be a valid scene.
  const Scene scene = parse_scene(text, o.path);
  write_file_atomic(o.path, text);
  const Vec3 size = scene.bounds().size();
  if (mesh) {
    fmt::print(
        "wrote {}: the part {} encloses ({:g} x {:g} x {:g} mm, its box) graded from {} at its bottom to {} "
        "at its top, for printer {}\n",
        o.path, o.mesh, size.x, size.y, size.z, scene.materials[0].name, scene.materials[1].name, scene.printer.name);
    if (!mesh->passed)
      fmt::print("note: the mesh is {}; the scene decides its inside by the winding number, which tolerates that\n",
                 mesh->problems);
  } else {
    fmt::print("wrote {}: a {:g} x {:g} x {:g} mm box graded from {} to {} along x, for printer {}\n", o.path, size.x,
               size.y, size.z, scene.materials[0].name, scene.materials[1].name, scene.printer.name);
  }
  for (const std::string& w : colour_warnings(scene, job_preview_background(scene, JobParams{})))
    fmt::print("warning: {}\n", w);
  fmt::print("next: trivox validate {0}   (checks it and estimates the job)\n", o.path);
  fmt::print("      trivox slice {0} -o {1}   (prints it)\n", o.path,
             std::filesystem::path(o.path).stem().string() + "_out");
}

}  // namespace

void add_init_command(CLI::App& app) {
  auto opts = std::make_shared<InitOptions>();
  CLI::App* cmd = app.add_subcommand(
      "init",
      "Write a scene to start from: a box graded between two library materials (or, with --mesh, the part a mesh "
      "encloses), described in its own words");
  cmd->add_option("scene", opts->path, "the scene file to write (NAME.json)")->required();
  cmd->add_option("--printer", opts->scene.printer,
                  fmt::format("a built-in printer profile ({})", fmt::join(builtin_printer_profile_names(), ", ")))
      ->capture_default_str();
  cmd->add_option("--materials", opts->scene.materials,
                  "the two library materials of the gradient, comma-separated (docs/SCENE.md#material-library)")
      ->delimiter(',')
      ->expected(2)
      ->capture_default_str();
  cmd->add_option("--mesh", opts->mesh,
                  "a triangle mesh (.stl, .obj, .ply, .3mf, in mm): the scene fills the part it encloses, graded from "
                  "bottom to top, in the box around it");
  cmd->add_flag("--force", opts->force, "replace the file if it exists");
  cmd->callback([opts] { run_init(*opts); });
}

}  // namespace trivox::cli
