// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// SHA-256 digests (FIPS 180-4) of bytes and files, as lowercase hex: the same text that
// `sha256sum FILE` prints, so a user can check any file of a job by hand. Used for the job
// manifest (docs/FORMATS.md, "manifest.json"): the hashes of the scene, its models and every
// output file.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace trivox {

// Incremental digest: update() any number of times, then hex() once.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  void update(std::span<const std::uint8_t> bytes);
  void update(std::string_view bytes);
  // The digest of everything given so far, 64 lowercase hex digits. Ends the digest.
  std::string hex();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

std::string sha256_hex(std::string_view bytes);

// The digest of a file and its size in bytes, read in blocks. Throws IoError naming the path
// when it cannot be opened or read; CancelledError once `stop` (optional) is raised, read
// before each block.
struct FileDigest {
  std::uint64_t bytes = 0;
  std::string sha256;
};
FileDigest sha256_file(const std::filesystem::path& path, const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
