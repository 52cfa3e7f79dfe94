// A job whose scene reads a model file: the model's SHA-256 is in the manifest beside the
// scene's, and `--resume` refuses once the model has been edited, naming it, and accepts it
// again once it is back as it was.
#include <filesystem>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/manifest.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

TEST(CliResume, AModelFileIsHashedInTheManifestAndAnEditRefusesResume) {
  ScratchDir dir;
  fs::create_directories(dir.path() / "scenes");
  fs::create_directories(dir.path() / "models");
  fs::copy_file(examples_dir() / "scenes" / "column_scalar_gradient.json", dir.path() / "scenes" / "column.json");
  const fs::path model = dir.path() / "models" / "twisted_column.itd";
  fs::copy_file(examples_dir() / "models" / "twisted_column.itd", model);
  const fs::path out = dir.path() / "out";
  const std::string args =
      "slice " + shell_quote(dir.path() / "scenes" / "column.json") + " --layers 1:4 -q -j 2 -o " + shell_quote(out);
  const CliResult first = run_cli(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;

  const JobManifest m = read_manifest(out / "manifest.json");
  ASSERT_EQ(m.inputs.size(), 2u);
  EXPECT_EQ(m.inputs[1].role, "model");
  EXPECT_EQ(m.inputs[1].name, "../models/twisted_column.itd");
  EXPECT_EQ(m.inputs[1].sha256, sha256_file(model).sha256);
  const auto before = folder_bytes(out);

  // One control point moved by 0.0556 mm.
  std::string text = read_text(model);
  const std::size_t at = text.find("[4.4444 0 0]");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 12, "[4.5 0 0]");
  write_text(model, text);
  const CliResult refused = run_cli(args + " --resume");
  EXPECT_EQ(refused.exit_code, 3) << refused.err;
  EXPECT_NE(refused.err.find("model \"../models/twisted_column.itd\" has changed"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find((out / "manifest.json").string()), std::string::npos) << refused.err;
  EXPECT_EQ(folder_bytes(out), before);  // the refusal changed nothing

  // The original model back: the job resumes, with nothing left to do.
  fs::copy_file(examples_dir() / "models" / "twisted_column.itd", model, fs::copy_options::overwrite_existing);
  const CliResult resumed = run_cli(args + " --resume");
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("30 layers were already complete"), std::string::npos) << resumed.out;
  EXPECT_EQ(folder_bytes(out), before);
}

}  // namespace
}  // namespace trivox::test
