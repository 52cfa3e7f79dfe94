// The bundled chalice (examples/scenes/chalice.json) sliced whole by the trivox program, as
// the README's demo does in part: every layer, no pixel left unresolved or found folded, the
// five cells that print each owning pixels and the two empty regions none, the clear
// material dominant and every colour present.
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli_run.h"

namespace trivox::test {
namespace {

const std::filesystem::path kChalice = examples_dir() / "scenes" / "chalice.json";

TEST(Chalice, WholeChaliceSlicesWithoutUnresolvedOrFoldedPixels) {
  ScratchDir dir;
  const CliResult r =
      run_cli("slice " + shell_quote(kChalice) + " -o " + shell_quote(dir.path()) + " --format preview -q -j 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(read_text(dir.path() / "stats.json"));
  const nlohmann::json& t = stats.at("total");
  EXPECT_EQ(t.at("layers_sliced").get<int>(), 1001);  // 27 mm in 0.027 mm High Mix layers
  EXPECT_EQ(t.at("unresolved_pixels").get<long>(), 0);
  EXPECT_EQ(t.at("folded_pixels").get<long>(), 0);
  const long inside = t.at("pixels_inside").get<long>();
  EXPECT_GT(inside, 20'000'000);

  // Cells in scene order: base, knot, cup, knot in base, knot in cup, base+cup, all three.
  const auto names = stats.at("cells").get<std::vector<std::string>>();
  ASSERT_EQ(names, (std::vector<std::string>{"chalice/base", "chalice/knot", "chalice/cup", "chalice/knot in base",
                                             "chalice/knot in cup", "chalice/base+cup", "chalice/base+knot+cup"}));
  const auto owned = t.at("pixels_per_cell").get<std::vector<long>>();
  ASSERT_EQ(owned.size(), 7u);
  for (std::size_t c = 0; c < 5; ++c) EXPECT_GT(owned[c], 50'000) << names[c];
  EXPECT_EQ(owned[5], 0);
  EXPECT_EQ(owned[6], 0);
  EXPECT_EQ(std::accumulate(owned.begin(), owned.end(), 0L), inside);

  // Mostly clear, with every colour somewhere.
  const auto per = t.at("voxels_per_material").get<std::vector<long>>();
  ASSERT_EQ(per.size(), 4u);
  EXPECT_GT(per[0], 4 * (per[1] + per[2] + per[3]));
  for (std::size_t m = 1; m < 4; ++m) EXPECT_GT(per[m], 10'000) << m;
}

}  // namespace
}  // namespace trivox::test
