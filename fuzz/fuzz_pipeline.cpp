// libFuzzer entry for the whole-pipeline target (fuzz/harness/fuzz_harness.h, run_pipeline):
// generated scenes with extreme but legal values, sliced for 1 to 3 layers in a private
// temporary folder. With TRIVOX_FUZZ_PIPELINE_LOG set, one line per input is appended to
// that file (outcome, pixels, seconds, heap growth and estimate in MB, refusal), from which
// scripts/fuzz.sh reports how many jobs were sliced, the heap over the estimate and the
// slowest input.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "harness/fuzz_harness.h"

namespace {

std::filesystem::path work_dir;
std::FILE* log_file = nullptr;

const char* kind_name(trivox::fuzz::PipelineOutcome::Kind kind) {
  switch (kind) {
    case trivox::fuzz::PipelineOutcome::Kind::kSliced: return "sliced";
    case trivox::fuzz::PipelineOutcome::Kind::kTooLarge: return "too-large";
    case trivox::fuzz::PipelineOutcome::Kind::kStopped: return "stopped";
    case trivox::fuzz::PipelineOutcome::Kind::kRefused: break;
  }
  return "refused";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  work_dir = std::filesystem::temp_directory_path() / ("trivox-fuzz-pipeline-" + std::to_string(::getpid()));
  std::filesystem::create_directories(work_dir);
  if (const char* log = std::getenv("TRIVOX_FUZZ_PIPELINE_LOG")) log_file = std::fopen(log, "a");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const trivox::fuzz::PipelineOutcome o = trivox::fuzz::run_pipeline({data, size}, work_dir);
  if (log_file) {
    std::string refusal = o.refusal;
    for (char& ch : refusal)
      if (ch == '\t' || ch == '\n') ch = ' ';
    std::fprintf(log_file, "%s\t%.0f\t%.4f\t%.2f\t%.2f\t%s\n", kind_name(o.kind), o.pixels, o.seconds,
                 o.heap_grown_bytes < 0 ? -1.0 : o.heap_grown_bytes / 1e6,
                 o.estimate_bytes < 0 ? -1.0 : o.estimate_bytes / 1e6, refusal.c_str());
    std::fflush(log_file);
  }
  return 0;
}
