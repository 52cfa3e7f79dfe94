// The whole-pipeline fuzz target's generator: bytes drive the choices of a small, valid scene
// with extreme but legal values (weights 1e-6 to 1e6, sizes 1e-6 to 1e6 mm, translations up
// to 1e308, collapsed and duplicated control points, orders 1 to 16, repeated knots, every
// material kind that needs no file, custom printers, every tolerance option, every output
// format), and of the job that slices 1 to 3 of its layers. Structure-aware: every input
// gives a scene that is at least well formed JSON of the scene format, so the fuzzer spends
// its time behind the parsers, in the geometry, the slicer and the writers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace trivox::fuzz {

// Reads choices from the input's bytes; once they run out every choice is its first option
// (zero), so every input, even an empty one, is a complete description.
class ByteChoices {
 public:
  explicit ByteChoices(std::span<const std::uint8_t> data) : data_(data) {}
  std::uint32_t u32();
  // 0 .. n - 1 (n >= 1).
  int pick(int n) { return static_cast<int>(u32() % static_cast<std::uint32_t>(n)); }
  bool coin() { return pick(2) == 1; }
  // A number in [0, 1).
  double unit() { return u32() / 4294967296.0; }
  // lo * (hi / lo)^t for a uniform t: every order of magnitude equally likely (lo, hi > 0).
  double log_uniform(double lo, double hi);

 private:
  std::span<const std::uint8_t> data_;
  std::size_t at_ = 0;
};

struct PipelineJob {
  std::string scene_json;
  // The slicer's settings beyond the scene.
  std::string tracing = "flood";
  double residual_tolerance_mm = 1e-6;
  std::optional<double> outline_tolerance_mm;
  // The job: formats, which of the model's layers (as fractions of the range, mapped once
  // the layout is known), threads.
  std::vector<std::string> formats{"voxelprint"};
  double first_layer_fraction = 0.5;
  int layer_count = 1;
  int threads = 1;
  // Files the scene names, written into the work folder before it is read: name, bytes (a
  // mesh trim's STL: a box, doubled, a stack of coplanar faces, a malformed vertex).
  std::vector<std::pair<std::string, std::string>> files;
  // The construction cache (the first cell then built by a constructor): 0, none; else the
  // scene is read once with a cache in the work folder, every entry there damaged
  // (kCacheDamage), and read again, which must give the volumes a read without the cache gives.
  int cache_damage = 0;
};

// How a staged cache entry is damaged: cut short, replaced by a directory, by a FIFO, by a
// link to /dev/zero, or its volume stretched and sealed again with its SHA-256 recomputed.
enum CacheDamage : int { kNoCache, kTruncated, kDirectory, kFifo, kDeviceLink, kReplacedGeometry, kCacheDamages };

PipelineJob generate_pipeline_job(std::span<const std::uint8_t> data);

}  // namespace trivox::fuzz
