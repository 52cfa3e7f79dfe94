// libFuzzer entry for the scene target (fuzz/harness/fuzz_harness.h says what it checks).
// Scenes resolve model files against a private temporary folder filled once at start-up.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "harness/fuzz_harness.h"

namespace {

std::filesystem::path scene_dir;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  scene_dir = std::filesystem::temp_directory_path() / ("trivox-fuzz-scene-" + std::to_string(::getpid()));
  trivox::fuzz::prepare_scene_dir(scene_dir, TRIVOX_EXAMPLES_MODELS_DIR);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  trivox::fuzz::run_scene({data, size}, scene_dir);
  return 0;
}
