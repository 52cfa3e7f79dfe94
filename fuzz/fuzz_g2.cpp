// libFuzzer entry for the g2 target (fuzz/harness/fuzz_harness.h says what it checks).
#include <cstddef>
#include <cstdint>

#include "harness/fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  trivox::fuzz::run_g2({data, size});
  return 0;
}
