// What each fuzz target does with one input, shared by the libFuzzer programs (fuzz/*.cpp)
// and the regression test that replays the checked-in inputs in every build
// (tests/fuzz/fuzz_regressions_test.cpp).
//
// The contract under test: any bytes given to a reader end in a result or in one of the
// library's documented errors (trivox::Error and its subclasses). Each function returns
// normally in both cases. Anything else - another exception type, a crash, a leak, undefined
// behaviour, a result that breaks the reader's own promises (a written model that does not
// read back) - escapes, and the fuzzer reports it as a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string_view>

namespace trivox::fuzz {

// A reader returned something that breaks its documented guarantees.
class HarnessViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// The targets, by the name used for fuzz/corpus/<name> and fuzz/regressions/<name>.
inline constexpr std::string_view kTargets[] = {"itd", "gismo_xml", "scene",      "expression",
                                                "g2",  "pipeline",  "cache_entry"};

// IRIT .itd text: read_itd; an accepted model must survive write_itd and read back with the
// same patch count.
void run_itd(std::span<const std::uint8_t> data);
// G+Smo XML: read_gismo_xml; same round trip through write_itd.
void run_gismo_xml(std::span<const std::uint8_t> data);
// GoTools .g2 text: read_g2; an accepted model must survive write_g2 and read back with
// identical knots, coordinates and weights (the writer's promise for a model read from .g2),
// and survive write_itd like the other readers' models.
void run_g2(std::span<const std::uint8_t> data);
// Scene JSON text: parse_scene as if the file were `scene_dir`/scene.json (model files named
// by the scene resolve there, see prepare_scene_dir); an accepted scene's materials are then
// evaluated at the corners and centre of every cell.
void run_scene(std::span<const std::uint8_t> data, const std::filesystem::path& scene_dir);
// Expression materials: each line of the input is one material's expression (at most 8);
// the material is built over a cell domain and evaluated on a short row of samples.
void run_expression(std::span<const std::uint8_t> data);

// A construction cache entry (trivox/scene/construction_cache.h), under the key its header
// names: decode_construction_entry, whose accepted volume must encode back to the same bytes;
// then the bytes as the entry's file in `work_dir`/cache, which ConstructionCache::load must
// take (the same volume) or refuse with a warning, never an exception.
void run_cache_entry(std::span<const std::uint8_t> data, const std::filesystem::path& work_dir);

// Damages the construction cache entry at `entry` as `damage` (pipeline_job.h, CacheDamage)
// says: what the pipeline target does to the entries it stages, and the tests to theirs.
void damage_cache_entry(const std::filesystem::path& entry, int damage);

// The whole pipeline (pipeline_job.h): a valid scene with extreme values generated from the
// bytes, read, prepared for slicing within a memory limit of 256 MB beyond what the process
// holds, estimated and checked like `trivox slice` does, then 1 to 3 of its layers sliced
// into `work_dir`/job in every format asked. It must end in a result or a documented error;
// a completed job must pass verify_output; and in builds with AddressSanitizer the heap the
// job itself grows by must stay within 1.5 times the job's own memory estimate plus 64 MB.
// Jobs of more than 1e6 pixels (weighted by the orders, and 64 times without tracing) are not sliced, and models whose
// faces span more than 1e6 pixels not prepared: the fuzzer's time limit, 10 s, holds for
// those within.
struct PipelineOutcome {
  enum class Kind {
    kRefused,   // a documented error: bad or unworkable input, or too large for the limits
    kTooLarge,  // prepared and estimated, not sliced: more pixels than the fuzzer's budget
    kSliced,    // the layers were sliced, written and verified
    kStopped,   // stopped after kPipelineStopSeconds (fuzz_harness.cpp) and checked as interrupted
  };
  Kind kind = Kind::kRefused;
  std::string refusal;  // the error's message (first 160 characters) when refused
  double pixels = 0;    // the job's pixels (width x height x layers), once laid out
  double seconds = 0;   // wall time of the whole input
  // Heap growth while slicing and the job's own estimate of it, in bytes (AddressSanitizer
  // builds only; negative where not measured).
  double heap_grown_bytes = -1;
  double estimate_bytes = -1;
};

PipelineOutcome run_pipeline(std::span<const std::uint8_t> data, const std::filesystem::path& work_dir);

// Fills `dir` with the files a fuzzed scene may name: models/box.itd (a trilinear box),
// models/box.xml (the same box in G+Smo XML) and the bundled example models copied from
// `examples_models` when that folder exists. Scenes then live in dir/scenes/.
void prepare_scene_dir(const std::filesystem::path& dir, const std::filesystem::path& examples_models);

// Dispatches on a target name from kTargets (false for an unknown name).
bool run_target(std::string_view target, std::span<const std::uint8_t> data, const std::filesystem::path& scene_dir);

}  // namespace trivox::fuzz
