// Internal to trivox, not part of its stable interface (docs/ARCHITECTURE.md, "Public surface").

// The one place an input file's kind is checked before it is read: model, scene and mesh
// files named by a scene, and construction cache entries. A path that names a directory, a
// FIFO, a device or a socket (or a link to one) is refused by what it is, never read: /dev/zero
// would fill memory, a FIFO would block the job, a directory reads as an error from the C
// library that names no path.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace trivox {

// What `path` names when it is not a regular file, following links: "no file", "a
// directory", "a FIFO", "a character device", "a block device", "a socket", "not a regular
// file", "a path that cannot be examined (REASON)"; nullopt for a regular file (or a link to
// one).
std::optional<std::string> not_a_regular_file(const std::filesystem::path& path);

// The bytes of the regular file at `path`, read whole. The file is opened without blocking
// (O_NONBLOCK, so that a FIFO put in its place returns at once) and its kind and size are
// taken from the opened descriptor (fstat), so that what is read is what was checked: a
// regular file of at most `max_bytes`, else IoError naming the path and what it is, before
// anything is allocated. A file that changes size while it is read is an IoError too. `stop`
// (optional) is read before each 16 MiB read: once it is raised, CancelledError.
std::string read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                              const std::atomic<bool>* stop = nullptr);

}  // namespace trivox
