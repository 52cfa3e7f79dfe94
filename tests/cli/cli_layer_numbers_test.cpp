// One numbering of layers for a person (CLI.md, "Layer numbers"): --layers, --preview, the
// summary, the preview's name and stats.json count the model's layers from 1; the layer files
// number the stack from 1.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

TEST(CliLayerNumbers, LayersPreviewSummaryAndStatsCountTheModelsLayersFromOne) {
  ScratchDir dir;
  const fs::path out = dir.path() / "num";
  const CliResult r = run_cli("slice " + shell_quote(examples_dir() / "scenes" / "quick_start.json") +
                              " --layers 100:104 --preview 102 --min-layers 0 -q -o " + shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sliced 5 layers (709 x 355 px, layers 100 to 104 of the model's 223) into"), std::string::npos)
      << r.out;
  EXPECT_TRUE(fs::exists(out / "preview" / "layer_00102.png"));
  EXPECT_TRUE(fs::exists(out / "slice_00001.png"));  // the stack's first layer: the model's 100th
  EXPECT_TRUE(fs::exists(out / "slice_00005.png"));
  EXPECT_FALSE(fs::exists(out / "slice_00006.png"));
  const nlohmann::json stats = nlohmann::json::parse(read_text(out / "stats.json"));
  std::vector<int> layers;
  for (const nlohmann::json& layer : stats.at("layers")) layers.push_back(layer.at("layer").get<int>());
  EXPECT_EQ(layers, (std::vector<int>{100, 101, 102, 103, 104}));
  // One layer of the model is named as one.
  const CliResult one = run_cli("slice " + shell_quote(examples_dir() / "scenes" / "quick_start.json") +
                                " --layers 7:7 --min-layers 0 -q -o " + shell_quote(dir.path() / "one"));
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_NE(one.out.find("sliced 1 layer (709 x 355 px, layer 7 of the model's 223) into"), std::string::npos)
      << one.out;
  EXPECT_NE(one.out.find(" px, 1 layer); model: "), std::string::npos) << one.out;  // the printed extent too
  // A resume that finds one layer complete says so in the singular.
  const CliResult again = run_cli("slice " + shell_quote(examples_dir() / "scenes" / "quick_start.json") +
                                  " --layers 7:7 --min-layers 0 -q --resume -o " + shell_quote(dir.path() / "one"));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("resumed: 1 layer was already complete"), std::string::npos) << again.out;
}

}  // namespace
}  // namespace trivox::test
