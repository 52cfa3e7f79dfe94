// The subcommands of the trivox program. Each command lives in its own cmd_<name>.cpp and
// has one entry point that adds the subcommand, its options and its callback to the
// application. Adding a command is: write cmd_<name>.cpp with add_<name>_command, declare it
// here and list it in kCommands (the order is the order of `trivox --help`).
//
// Commands report failures by throwing: trivox::Error subclasses for bad input and I/O, and
// UsageError (cli_errors.h) for a command line that parses but cannot be carried out (an
// option value out of its set, a patch the model does not have). main() alone turns them
// into messages and exit codes.
#pragma once

#include <array>
#include <string>

namespace CLI {
class App;
}

namespace trivox::cli {

// `trivox info MODEL [--json]`: patches, orders, control points, domains, bounds and a
// sampled Jacobian check per trivariate.
void add_info_command(CLI::App& app);

// `trivox probe MODEL [--eval --patch N]`: evaluates parameters or inverts model-space points
// read from standard input, one JSON line per input line.
void add_probe_command(CLI::App& app);

// `trivox slice SCENE -o DIR`: printer-ready layer images of a scene, with stats.json.
void add_slice_command(CLI::App& app);

// `trivox build SPEC -o OUT.itd`: a volume made by a constructor, saved as a model file.
void add_build_command(CLI::App& app);

// `trivox validate SCENE [job options]`: checks a job before it runs and estimates its cost.
void add_validate_command(CLI::App& app);
// What `trivox info SCENE.json` prints: the scene and the estimate of a default job.
void print_scene_info(const std::string& scene_path);

// `trivox merge DIR`: one manifest.json from the shard manifests of a split job.
void add_merge_command(CLI::App& app);

// `trivox verify DIR`: re-hashes and decodes every file manifest.json lists.
void add_verify_command(CLI::App& app);

// `trivox init NAME.json`: a scene to start from, a box with a two-material gradient.
void add_init_command(CLI::App& app);

// `trivox cluster slurm SCENE -o DIR --shards N`: the batch scripts of a sharded job on Slurm.
void add_cluster_command(CLI::App& app);

using AddCommand = void (*)(CLI::App&);
inline constexpr std::array<AddCommand, 9> kCommands = {&add_init_command,  &add_slice_command,  &add_validate_command,
                                                        &add_merge_command, &add_verify_command, &add_cluster_command,
                                                        &add_info_command,  &add_probe_command,  &add_build_command};

}  // namespace trivox::cli
