// Atomic file replacement: every file trivox writes goes to a temporary name beside its
// target, is flushed and fsync'ed, and only then renamed over the target. A job killed at
// any moment leaves either the old file, the new file, or neither under the final name -
// never a truncated one. A process killed mid-write may leave its temporary
// ("<name>.tmp-<pid>-<n>@<host>": its process and its machine, since the shards of one job
// may write into one shared folder from several machines); remove_stale_temporaries() clears
// those before a job resumes.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
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

// True for a name AtomicFile gives its temporaries ("<name>.tmp-<digits>-<digits>", then
// "@<host>"; earlier releases wrote no host).
bool is_atomic_temporary_name(std::string_view file_name) noexcept;

// This machine's name as temporaries and lock files record it: gethostname(), cut to 64
// bytes, characters other than letters, digits, '.', '-' and '_' replaced by '_'.
std::string machine_name();

// Whether a process `pid` runs on this machine now (one of another user counts: kill(2)
// answers EPERM); false for a pid that is not positive. How temporaries and lock lines are
// judged by the pid they name, on the machine they name.
bool process_runs_here(long pid) noexcept;

// Whose temporaries remove_stale_temporaries() may judge. A process on another machine cannot
// be seen from this one, so its temporaries are removed only when no job can be writing
// anywhere: a whole job (it holds the folder exclusively) or a merge.
enum class StaleTemporaries {
  kOfThisMachine,   // those of this machine whose process has ended (a shard's resume)
  kOfEveryMachine,  // those of this machine whose process has ended, and every other machine's
};

// Removes the AtomicFile temporaries in `dir` and its subfolders that `scope` judges stale;
// a process still running on this machine (the pid in the name: another shard of the job
// writing into the same folder) keeps its own. A name without a host (an earlier release's)
// counts as this machine's. Returns how many it removed.
int remove_stale_temporaries(const std::filesystem::path& dir,
                             StaleTemporaries scope = StaleTemporaries::kOfThisMachine);

}  // namespace trivox
