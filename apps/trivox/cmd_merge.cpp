// `trivox merge DIR`: joins the shards of a split job (docs/CLI.md#merge).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "commands.h"
#include "stop_signal.h"
#include "trivox/job/job_folder.h"

namespace trivox::cli {

void add_merge_command(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* cmd =
      app.add_subcommand("merge", "Join the shard manifests of a job sliced with --shard into manifest.json");
  cmd->add_option("dir", *dir, "Output folder the shards were sliced into")->required();
  cmd->callback([dir] {
    const JobManifest m = merge_shards(*dir, stop_on_signals());
    fmt::print("merged the shards: {} layers, {} files; manifest: {}\n", m.total_layers, m.files.size(),
               (std::filesystem::path(*dir) / "manifest.json").string());
    if (m.status != JobStatus::kComplete) fmt::print("{}\n", m.message);
  });
}

}  // namespace trivox::cli
