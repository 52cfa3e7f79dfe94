// Atomic file replacement: every file trivox writes goes to a temporary name beside its
// target, is flushed and fsync'ed, and only then renamed over the target. A job killed at
// any moment leaves either the old file, the new file, or neither under the final name -
// never a truncated one. A process killed mid-write may leave its temporary
// ("<name>.tmp-<pid>-<n>"); remove_stale_temporaries() clears those before a job resumes.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace trivox {

// A temporary file beside `target`, created exclusively. commit() makes its bytes durable
// and renames it over the target; if commit() is never reached, the destructor closes and
// removes it. Throws IoError naming the target (and the temporary) on every failure.
class AtomicFile {
 public:
  explicit AtomicFile(const std::filesystem::path& target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* file() const noexcept { return file_; }
  const std::filesystem::path& temporary() const noexcept { return path_; }
  // Writes `bytes` to the temporary file; throws IoError naming the target when it cannot.
  void write(std::string_view bytes);
  void commit();

 private:
  [[noreturn]] void fail(const char* what, int error_number) const;

  std::filesystem::path target_;
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// Writes `bytes` to `path` through an AtomicFile.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

// True for a name AtomicFile gives its temporaries ("<name>.tmp-<digits>-<digits>").
bool is_atomic_temporary_name(std::string_view file_name) noexcept;

// Removes every AtomicFile temporary in `dir` and its subfolders, except those of a process
// that still runs on this machine (the pid in the name: another shard of the job writing into
// the same folder); returns how many it removed.
int remove_stale_temporaries(const std::filesystem::path& dir);

}  // namespace trivox
