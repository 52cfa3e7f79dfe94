// A scratch file that holds one blob per job layer for a stack output. Layers finish in any
// order on several threads; each worker encodes its layer (the expensive part, in parallel)
// and appends the bytes here, and finish() reads them back in layer order, one in memory at
// a time. The file is removed when the spool is destroyed.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::detail {

class LayerSpool {
 public:
  // Creates (or truncates) `path` for `layers` blobs. Throws IoError naming it on failure.
  LayerSpool(std::filesystem::path path, int layers);
  ~LayerSpool();
  LayerSpool(const LayerSpool&) = delete;
  LayerSpool& operator=(const LayerSpool&) = delete;

  // Stores the blob of layer `index` (0-based); safe to call from several threads at once.
  // A layer stored again replaces its earlier blob.
  void put(int index, std::string_view bytes);
  // True once layer `index` has a blob.
  bool has(int index) const;
  // The size of layer `index`'s blob; 0 when it has none.
  std::uint64_t size(int index) const;
  // The blob of layer `index`. Throws Error when the layer never arrived, IoError when the
  // spool cannot be read.
  std::string get(int index) const;
  const std::filesystem::path& path() const noexcept { return path_; }

 private:
  struct Slot {
    std::uint64_t offset = 0, size = 0;
    bool stored = false;
  };
  std::filesystem::path path_;
  mutable std::mutex mutex_;
  std::FILE* file_ = nullptr;
  std::uint64_t end_ = 0;
  std::vector<Slot> slots_;
};

}  // namespace trivox::detail
