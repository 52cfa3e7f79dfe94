// Constructed volumes kept between runs (docs/SLICING.md, "The construction cache"): a
// scene's constructed geometry (an untangled Coons volume takes about a second to build) is
// stored in a folder, one file per volume, named by the SHA-256 of everything that builds it:
// the constructor's JSON as read (canonical: key order and whitespace do not matter), the
// SHA-256 of every model file it names, and the identity of the running program (the SHA-256
// of its executable, so that a rebuilt trivox never takes a volume an older build made). The
// scene reader asks the cache before it builds (SceneReadOptions::construction_cache) and
// stores what it built; `trivox slice` keeps the cache in the output folder, so that repeated
// runs, --resume and the shards of a job build each volume once.
//
// An entry holds the volume's spline and its construction report exactly (every double as its
// 8 bytes) behind a header that names the key and the SHA-256 of the rest. An entry that is
// missing or of other inputs is built again; one that is damaged (truncated, altered, of
// another key), not a regular file (a directory, a FIFO, a device, a link to one) or larger
// than any volume's entry can be, is built again with a warning, never used; the scene reader
// also checks a loaded volume against its inputs at a few points (its faces against the
// surfaces that build them) and builds again, with a warning, one that disagrees, as an entry
// replaced with its digest recomputed would; entries are written atomically
// (output/atomic_file.h), so two processes storing the same volume at once leave one whole
// file. Failing to read or write the cache never fails the reading of the scene: a warning.
#pragma once

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/construct/report.h"

namespace trivox {

class ConstructionCache {
 public:
  // `dir`: the cache's folder, created when the first entry is stored.
  explicit ConstructionCache(std::filesystem::path dir);
  // A cache whose program identity is given rather than computed from the executable (""
  // turns the cache off): for the fuzzer and tests, which would otherwise hash their own
  // program once per cache.
  ConstructionCache(std::filesystem::path dir, std::string program_identity);

  const std::filesystem::path& dir() const noexcept { return dir_; }

  // The volume stored under `key` (64 hex digits), or nullopt when there is none, or it is
  // damaged (a warning), or the running program cannot be identified (a warning, once; the
  // cache is then not used). `stop` (optional) is read while the entry is read: once it is
  // raised, CancelledError.
  std::optional<Constructed> load(const std::string& key, const std::atomic<bool>* stop = nullptr);
  // Stores `built` under `key`, replacing a damaged entry; a failure is a warning.
  void store(const std::string& key, const Constructed& built);
  // Takes back the volume load() returned for `key`: its caller found that it does not agree
  // with the inputs that build it (`why`, a warning); the volume is then built again and
  // stored, replacing the entry. Not counted as a hit.
  void reject(const std::string& key, const std::string& why);

  // What the keys include beside the construction: the program's identity ("" when it cannot
  // be identified: the cache is then not used). Computed once, on first use.
  const std::string& program_identity();

  // The path of the entry for `key`.
  std::filesystem::path entry_path(const std::string& key) const;

  int hits() const noexcept { return hits_; }      // volumes load() returned
  int stored() const noexcept { return stored_; }  // entries store() wrote
  // Damaged entries, entries that could not be read or written, an unidentified program; in
  // the order they happened.
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }

 private:
  std::filesystem::path dir_;
  std::optional<std::string> identity_;
  int hits_ = 0, stored_ = 0;
  std::vector<std::string> warnings_;
};

// The name of the cache's folder inside a job's output folder.
inline constexpr std::string_view kConstructionCacheFolder = ".trivox-cache";

// An entry's bytes (docs/FORMATS.md, "Construction cache entry"), and back: decode returns
// nullopt, with the reason in `problem`, for bytes that are not a whole entry for `key`.
// Exposed for the tests.
std::string encode_construction_entry(const std::string& key, const Constructed& built);
std::optional<Constructed> decode_construction_entry(std::string_view bytes, const std::string& key,
                                                     std::string* problem);

// The SHA-256 (hex) of the program file that holds this code: the executable, or the shared
// library when trivox is loaded as one; nullopt when it cannot be found or read.
std::optional<std::string> this_program_sha256();

}  // namespace trivox
