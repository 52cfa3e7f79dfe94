// `trivox init [--printer P] [--materials A,B] NAME.json`: writes a scene to start from, a box
// graded between two library materials that slices as is (docs/CLI.md#init).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_errors.h"
#include "commands.h"
#include "job_options.h"
#include "trivox/error.h"
#include "trivox/job/job.h"
#include "trivox/output/atomic_file.h"
#include "trivox/printer/printer_profile.h"
#include "trivox/scene/scene.h"
#include "trivox/scene/starter_scene.h"

namespace trivox::cli {

namespace {

struct InitOptions {
  std::string path;
  StarterSceneParams scene;
  bool force = false;
};

void run_init(const InitOptions& o) {
  std::string text;
  try {
    text = starter_scene_text(o.scene);
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
  fmt::print("wrote {}: a {:g} x {:g} x {:g} mm box graded from {} to {} along x, for printer {}\n", o.path, size.x,
             size.y, size.z, scene.materials[0].name, scene.materials[1].name, scene.printer.name);
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
      "init", "Write a scene to start from: a box graded between two library materials, described in its own words");
  cmd->add_option("scene", opts->path, "the scene file to write (NAME.json)")->required();
  cmd->add_option("--printer", opts->scene.printer,
                  fmt::format("a built-in printer profile ({})", fmt::join(builtin_printer_profile_names(), ", ")))
      ->capture_default_str();
  cmd->add_option("--materials", opts->scene.materials,
                  "the two library materials of the gradient, comma-separated (docs/SCENE.md#material-library)")
      ->delimiter(',')
      ->expected(2)
      ->capture_default_str();
  cmd->add_flag("--force", opts->force, "replace the file if it exists");
  cmd->callback([opts] { run_init(*opts); });
}

}  // namespace trivox::cli
