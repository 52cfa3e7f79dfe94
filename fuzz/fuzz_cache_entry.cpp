// libFuzzer entry for the cache_entry target (fuzz/harness/fuzz_harness.h says what it checks).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "harness/fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // One folder per process, kept between inputs: each input replaces the entry it writes.
  static const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("trivox-fuzz-cache-entry-" + std::to_string(::getpid()));
  trivox::fuzz::run_cache_entry({data, size}, work);
  return 0;
}
