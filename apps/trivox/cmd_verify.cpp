// `trivox verify DIR`: checks an output folder against its manifest (docs/CLI.md#verify).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli_errors.h"
#include "commands.h"
#include "stop_signal.h"
#include "trivox/job/job_folder.h"

namespace trivox::cli {

void add_verify_command(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("verify", "Re-hash and decode every file an output folder's manifest.json lists");
  cmd->add_option("dir", *dir, "Output folder of `trivox slice`")->required();
  cmd->callback([dir] {
    const VerifyReport r = verify_output(*dir, stop_on_signals());
    for (const std::string& p : r.problems) fmt::print("{}\n", p);
    if (!r.ok())
      throw CorruptOutputError(
          fmt::format("{}: {} problem(s) in {} files checked", *dir, r.problems.size(), r.files_checked));
    fmt::print("ok: {} layers, {} files match manifest.json\n", r.manifest.total_layers, r.files_checked);
  });
}

}  // namespace trivox::cli
