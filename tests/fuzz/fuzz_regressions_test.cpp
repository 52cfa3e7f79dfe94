// Replays every checked-in fuzz input - the inputs that once broke a reader
// (fuzz/regressions/<target>/) and the seed corpora (fuzz/corpus/<target>/) - through the
// same harness the libFuzzer programs run, so each fix stays checked in every build, not
// only in fuzz builds. An input passes when the reader returns or throws one of the
// library's documented errors (fuzz/harness/fuzz_harness.h).
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "harness/fuzz_harness.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs_of(const std::string& target, const char* kind) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(TRIVOX_FUZZ_DIR) / kind / target;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FuzzInputs : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzInputs, EveryCheckedInInputEndsInAResultOrADocumentedError) {
  ScratchDir scene_dir;
  fuzz::prepare_scene_dir(scene_dir.path(), examples_dir() / "models");
  const auto regressions = inputs_of(GetParam(), "regressions");
  const auto seeds = inputs_of(GetParam(), "corpus");
  ASSERT_FALSE(seeds.empty()) << "no seed corpus under fuzz/corpus/" << GetParam();
  for (const auto* list : {&regressions, &seeds})
    for (const fs::path& file : *list) {
      const std::vector<std::uint8_t> bytes = read_bytes(file);
      EXPECT_NO_THROW(fuzz::run_target(GetParam(), bytes, scene_dir.path())) << file;
    }
}

// The pipeline's seeds are there to reach the slicer: most of them must slice, write and
// verify a job, not be refused or skipped as too large (a generator change that stops that
// would leave the pipeline fuzzer testing the parsers only).
TEST(PipelineFuzzSeeds, MostSliceAndVerifyAJob) {
  ScratchDir work;
  const auto seeds = inputs_of("pipeline", "corpus");
  int sliced = 0;
  for (const fs::path& file : seeds) {
    const fuzz::PipelineOutcome o = fuzz::run_pipeline(read_bytes(file), work.path());
    sliced += o.kind == fuzz::PipelineOutcome::Kind::kSliced;
    if (o.kind != fuzz::PipelineOutcome::Kind::kSliced)
      std::cout << file.filename().string() << ": " << (o.refusal.empty() ? "too large" : o.refusal) << "\n";
  }
  EXPECT_GE(2 * sliced, static_cast<int>(seeds.size())) << sliced << " of " << seeds.size() << " seeds sliced a job";
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzInputs,
                         ::testing::ValuesIn(std::vector<std::string>(std::begin(fuzz::kTargets),
                                                                      std::end(fuzz::kTargets))),
                         [](const ::testing::TestParamInfo<std::string>& target) { return target.param; });

}  // namespace
}  // namespace trivox::test
