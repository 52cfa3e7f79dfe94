#include "trivox/job/job_lock.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

namespace {

std::string errno_text(int error_number) { return std::error_code(error_number, std::generic_category()).message(); }

// The first line of a lock file: who holds (or held) it.
std::string holder_line(int fd) {
  char buffer[512];
  const ssize_t n = pread(fd, buffer, sizeof buffer - 1, 0);
  if (n <= 0) return {};
  std::string text(buffer, static_cast<std::size_t>(n));
  text = text.substr(0, text.find('\n'));
  return text;
}

std::string holder_line(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  std::string line = holder_line(fd);
  ::close(fd);
  return line;
}

// The words of a holder line, "pid=1234 host=h task=slurm:7_2 started=T" (task only under a
// scheduler).
struct Holder {
  std::string pid, host, task, started;
};

Holder holder_of(const std::string& line) {
  Holder h;
  std::size_t at = 0;
  while (at < line.size()) {
    const std::size_t end = std::min(line.find(' ', at), line.size());
    const std::string word = line.substr(at, end - at);
    if (word.starts_with("pid=")) h.pid = word.substr(4);
    if (word.starts_with("host=")) h.host = word.substr(5);
    if (word.starts_with("task=")) h.task = word.substr(5);
    if (word.starts_with("started=")) h.started = word.substr(8);
    at = end + 1;
  }
  return h;
}

// "process 1234 on host h (task slurm:7_2), started T" from a holder line; the line itself
// when it is not in that form (written by hand, or truncated).
std::string holder_text(const std::string& line) {
  const Holder h = holder_of(line);
  if (h.pid.empty()) return line.empty() ? std::string("a process that has not yet said who it is") : "'" + line + "'";
  return fmt::format("process {}{}{}{}", h.pid, h.host.empty() ? "" : " on host " + h.host,
                     h.task.empty() ? "" : " (task " + h.task + ")", h.started.empty() ? "" : ", started " + h.started);
}

// The scheduler's task this process runs as: TRIVOX_TASK_ID when set, else Slurm's array task
// ("slurm:<array job>_<index>") or job ("slurm:<job>"); empty outside a scheduler.
std::string this_task() {
  const auto env = [](const char* name) {
    const char* value = std::getenv(name);
    return std::string(value == nullptr ? "" : value);
  };
  std::string task = env("TRIVOX_TASK_ID");
  if (task.empty() && !env("SLURM_ARRAY_JOB_ID").empty() && !env("SLURM_ARRAY_TASK_ID").empty())
    task = "slurm:" + env("SLURM_ARRAY_JOB_ID") + "_" + env("SLURM_ARRAY_TASK_ID");
  if (task.empty() && !env("SLURM_JOB_ID").empty()) task = "slurm:" + env("SLURM_JOB_ID");
  // Within an srun step, each process of it: two processes of one job are two tasks, while a
  // requeued job numbers its steps and processes again from 0.
  if (task.starts_with("slurm:") && !env("SLURM_STEP_ID").empty())
    task += fmt::format(".{}.{}", env("SLURM_STEP_ID"), env("SLURM_PROCID").empty() ? "0" : env("SLURM_PROCID"));
  for (char& c : task)
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  return task.substr(0, 128);
}

std::string this_holder_line() {
  const auto now = std::chrono::time_point_cast<std::chrono::seconds>(std::chrono::system_clock::now());
  const std::string task = this_task();
  return fmt::format("pid={} host={}{} started={:%Y-%m-%dT%H:%M:%SZ}\n", ::getpid(), machine_name(),
                     task.empty() ? "" : " task=" + task, now);
}

// Whether a lock's holder is an earlier run of this process's own task: the same task, and a
// process that is not running here (on another machine, or ended on this one). A scheduler
// runs one copy of a task at a time, so that run has ended - its node lost, the task requeued
// - though the file server may keep its lock until it notices (docs/CLUSTER.md, "Locks").
bool earlier_run_of_this_task(const std::string& line) {
  const Holder h = holder_of(line);
  const std::string task = this_task();
  if (task.empty() || h.task != task) return false;
  if (h.host != machine_name()) return true;
  const long pid = std::atol(h.pid.c_str());
  return pid > 0 && pid != static_cast<long>(::getpid()) && !process_runs_here(pid);
}

// Without flock (below): whether the job a lock file's line names has ended - a process of
// this machine that no longer runs, or an earlier run of this process's own task. A holder
// on another machine, or a line not written yet, counts as running.
bool holder_gone(const std::string& line) {
  if (earlier_run_of_this_task(line)) return true;
  const Holder h = holder_of(line);
  if (h.pid.empty() || h.host != machine_name()) return false;
  const long pid = std::atol(h.pid.c_str());
  return pid > 0 && pid != static_cast<long>(::getpid()) && !process_runs_here(pid);
}

// flock(2) answered that the file system has no such locks (ENOLCK: an NFS mount whose lock
// service cannot be reached; EOPNOTSUPP, ENOSYS: some FUSE and parallel file systems).
struct NoFlock {};

// TRIVOX_LOCKS=files: lock by the lock files alone, also where flock works.
bool locks_by_files_asked() {
  const char* value = std::getenv("TRIVOX_LOCKS");
  return value != nullptr && std::string_view(value) == "files";
}

// Without flock, a lock is its file: created with O_EXCL, held while it exists with the line
// of a job that runs. A file whose holder has ended is removed (its line returned in
// `taken_over`) and created again. Returns the descriptor, or -1 when a running job holds it.
int try_lock_by_file(const std::filesystem::path& path, std::optional<std::string>& taken_over) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) return fd;
    if (errno != EEXIST)
      throw IoError(fmt::format("{}: cannot create the lock file: {}", path.string(), errno_text(errno)));
    const std::string line = holder_line(path);
    if (!holder_gone(line)) return -1;
    taken_over = line;
    ::unlink(path.c_str());
  }
  return -1;
}

// The lock file opened without its lock, for a job that takes over from an earlier run of its
// own task; throws IoError naming it when it cannot be opened.
int open_unlocked(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(fmt::format("{}: cannot open the lock file: {}", path.string(), errno_text(errno)));
  return fd;
}

// Takes a flock of `mode` (LOCK_EX or LOCK_SH) on `path` without waiting. Returns the file
// descriptor, or -1 when another process holds a conflicting lock. A lock file is removed by
// the job that releases it last, so the file locked must still be the one under `path`:
// otherwise the lock was taken on a file just removed, and the loop opens the new one.
int try_lock(const std::filesystem::path& path, int mode) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    // Created here or found: a file created only to find that flock fails is removed again,
    // so that the lock files that replace flock then (take_lock_files) start from none.
    bool created = true;
    int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0 && errno == EEXIST) {
      created = false;
      fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    }
    if (fd < 0) throw IoError(fmt::format("{}: cannot create the lock file: {}", path.string(), errno_text(errno)));
    if (::flock(fd, mode | LOCK_NB) != 0) {
      const int error = errno;
      ::close(fd);
      if (error == EWOULDBLOCK) return -1;
      if (error == ENOLCK || error == EOPNOTSUPP || error == ENOSYS) {
        if (created) ::unlink(path.c_str());
        throw NoFlock{};
      }
      throw IoError(fmt::format("{}: cannot lock: {}", path.string(), errno_text(error)));
    }
    struct stat held {
    }, named{};
    if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
      return fd;
    ::close(fd);
  }
  throw IoError(fmt::format("{}: cannot lock: the lock file keeps being replaced", path.string()));
}

// Writes this process's holder line into an exclusively held lock file; returns its bytes.
std::uint64_t write_holder(int fd, const std::filesystem::path& path) {
  const std::string line = this_holder_line();
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, line.data(), line.size(), 0) != static_cast<ssize_t>(line.size()))
    throw IoError(fmt::format("{}: cannot write the lock file: {}", path.string(), errno_text(errno)));
  return line.size();
}

// Releases a lock: the file is removed first when no other process holds it (an exclusive
// lock, or a shared one that can become exclusive), so that a job never leaves it behind.
void release(int fd, const std::filesystem::path& path, bool exclusive) {
  if (fd < 0) return;
  if (exclusive || ::flock(fd, LOCK_EX | LOCK_NB) == 0) ::unlink(path.c_str());
  ::close(fd);
}

// The shards of `dir` whose lock is held now, as "shard I (process ...)", one holders text:
// `held` gives a shard lock file's holder line while it is held, nullopt when it is not.
std::string shards_held(const std::filesystem::path& dir,
                        const std::function<std::optional<std::string>(const std::filesystem::path&)>& held) {
  std::string holders;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(".trivox-shard-") || !name.ends_with(".lock")) continue;
    if (const std::optional<std::string> line = held(entry.path()))
      holders += fmt::format("{}shard {} ({})", holders.empty() ? "" : ", ", name.substr(14, name.size() - 14 - 5),
                             holder_text(*line));
  }
  return holders;
}

// With flock: a shard lock file is held while a process holds its lock.
std::optional<std::string> flock_held(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::optional<std::string> line;
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) line = holder_line(fd);
  ::close(fd);
  return line;
}

// Without flock: a shard lock file is held while its line names a job that runs.
std::optional<std::string> file_held(const std::filesystem::path& path) {
  std::string line = holder_line(path);
  if (holder_gone(line)) return std::nullopt;
  return line;
}

[[noreturn]] void refuse(const std::filesystem::path& dir, const std::filesystem::path& lock_file,
                         const std::string& holders) {
  throw Error(fmt::format(
      "{}: another trivox job is writing into this folder ({}; lock file {}): wait for it to end, or slice into "
      "another folder",
      dir.string(), holders, lock_file.string()));
}

}  // namespace

std::optional<std::string> output_folder_problem(const std::filesystem::path& dir) {
  const auto problem = [&](const std::string& reason) {
    return fmt::format("{}: cannot create output folder: {}", dir.string(), reason);
  };
  std::error_code ec;
  std::filesystem::path existing = dir.empty() ? std::filesystem::path(".") : dir;
  while (!std::filesystem::exists(std::filesystem::symlink_status(existing, ec)) && existing.has_relative_path()) {
    if (!existing.has_parent_path() || existing.parent_path() == existing) {
      existing = existing.is_absolute() ? existing.root_path() : std::filesystem::path(".");
      break;
    }
    existing = existing.parent_path();
  }
  const std::filesystem::file_status link = std::filesystem::symlink_status(existing, ec);
  const std::filesystem::file_status target = std::filesystem::status(existing, ec);
  if (std::filesystem::is_symlink(link) && !std::filesystem::exists(target))
    return problem(fmt::format("{} is a link to nothing", existing.string()));
  if (!std::filesystem::is_directory(target))
    return problem(existing == dir ? std::string("it exists and is not a folder")
                                   : fmt::format("{} exists and is not a folder", existing.string()));
  if (::access(existing.c_str(), W_OK | X_OK) != 0)
    return problem(fmt::format("{}: {}", existing.string(), errno_text(errno)));
  return std::nullopt;
}

std::string job_lock_file_name() { return ".trivox.lock"; }
std::string shard_lock_file_name(int shard_index) { return fmt::format(".trivox-shard-{}.lock", shard_index); }

struct JobFolderLock::Held {
  std::filesystem::path dir;
  int shard_index = 1, shard_count = 1;
  int folder_fd = -1;  // .trivox.lock
  int shard_fd = -1;   // .trivox-shard-I.lock, shards only
  std::optional<std::string> taken_over_from{};
  bool by_files = false;         // locked by the lock files alone (no flock on this file system)
  std::uint64_t line_bytes = 0;  // the holder line at the start of the job's own lock file
  std::uint64_t reserved = 0;    // bytes held after it

  void take_flocks();      // throws NoFlock when the file system has no flock locks
  void take_lock_files();  // without flock (locked_by_files)
};

JobFolderLock::JobFolderLock(const std::filesystem::path& dir, int shard_index, int shard_count)
    : held_(std::make_unique<Held>(Held{dir, shard_index, shard_count})) {
  Held& h = *held_;
  if (auto problem = output_folder_problem(h.dir)) throw IoError(std::move(*problem));
  std::error_code ec;
  std::filesystem::create_directories(h.dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create output folder: {}", h.dir.string(), ec.message()));
  if (!locks_by_files_asked()) {
    try {
      h.take_flocks();
      return;
    } catch (const NoFlock&) {
      h.folder_fd = h.shard_fd = -1;  // (released by take_flocks)
    }
  }
  h.by_files = true;
  h.take_lock_files();
}

void JobFolderLock::Held::take_flocks() {
  Held& h = *this;
  const std::filesystem::path folder_lock = h.dir / job_lock_file_name();
  const bool sharded = h.shard_count > 1;
  h.folder_fd = try_lock(folder_lock, sharded ? LOCK_SH : LOCK_EX);
  if (h.folder_fd < 0 && !sharded && earlier_run_of_this_task(holder_line(folder_lock)))
    h.folder_fd = open_unlocked(folder_lock);
  if (h.folder_fd < 0) {
    // A whole job holds it (its line is in the file), or running shards hold it shared.
    const std::string shards = shards_held(h.dir, flock_held);
    refuse(h.dir, folder_lock, shards.empty() ? holder_text(holder_line(folder_lock)) : shards);
  }
  if (!sharded) {
    const std::string previous = holder_line(h.folder_fd);
    if (!previous.empty()) h.taken_over_from = previous;
    try {
      h.line_bytes = write_holder(h.folder_fd, folder_lock);
    } catch (...) {
      release(h.folder_fd, folder_lock, true);
      throw;
    }
    return;
  }
  const std::filesystem::path shard_lock = h.dir / shard_lock_file_name(h.shard_index);
  try {
    h.shard_fd = try_lock(shard_lock, LOCK_EX);
  } catch (...) {
    release(h.folder_fd, folder_lock, false);
    throw;
  }
  if (h.shard_fd < 0 && earlier_run_of_this_task(holder_line(shard_lock))) h.shard_fd = open_unlocked(shard_lock);
  if (h.shard_fd < 0) {
    release(h.folder_fd, folder_lock, false);
    refuse(h.dir, shard_lock, holder_text(holder_line(shard_lock)));
  }
  const std::string previous = holder_line(h.shard_fd);
  if (!previous.empty()) h.taken_over_from = previous;
  try {
    h.line_bytes = write_holder(h.shard_fd, shard_lock);
  } catch (...) {
    release(h.shard_fd, shard_lock, true);
    release(h.folder_fd, folder_lock, false);
    throw;
  }
}

void JobFolderLock::Held::take_lock_files() {
  Held& h = *this;
  const std::filesystem::path folder_lock = h.dir / job_lock_file_name();
  const std::filesystem::path shard_lock = h.dir / shard_lock_file_name(h.shard_index);
  const bool sharded = h.shard_count > 1;
  // A whole job holds the folder's file; a shard its own, and is refused while a whole job's
  // file names a job that runs. Shards do not share the folder's file: a file cannot be held
  // shared, so a whole job looks for the shards' files instead.
  const std::filesystem::path own = sharded ? shard_lock : folder_lock;
  if (sharded) {
    std::error_code ec;
    if (std::filesystem::exists(folder_lock, ec) && !holder_gone(holder_line(folder_lock)))
      refuse(h.dir, folder_lock, holder_text(holder_line(folder_lock)));
  }
  int& fd = sharded ? h.shard_fd : h.folder_fd;
  fd = try_lock_by_file(own, h.taken_over_from);
  if (fd < 0) refuse(h.dir, own, holder_text(holder_line(own)));
  if (!sharded) {
    if (const std::string holders = shards_held(h.dir, file_held); !holders.empty()) {
      release(fd, own, true);
      fd = -1;
      refuse(h.dir, folder_lock, holders);
    }
  }
  try {
    h.line_bytes = write_holder(fd, own);
  } catch (...) {
    release(fd, own, true);
    fd = -1;
    throw;
  }
}

bool JobFolderLock::reserve_bytes(std::uint64_t bytes) {
  Held& h = *held_;
  const int fd = h.shard_fd >= 0 ? h.shard_fd : h.folder_fd;
  if (bytes <= h.reserved) return true;
  // Blocks actually allocated (not a sparse extension), so that freeing them makes room.
  if (::posix_fallocate(fd, static_cast<off_t>(h.line_bytes), static_cast<off_t>(bytes)) != 0) return false;
  h.reserved = bytes;
  return true;
}

void JobFolderLock::release_reserve() noexcept {
  Held& h = *held_;
  const int fd = h.shard_fd >= 0 ? h.shard_fd : h.folder_fd;
  if (h.reserved > 0 && ::ftruncate(fd, static_cast<off_t>(h.line_bytes)) == 0) h.reserved = 0;
}

JobFolderLock::~JobFolderLock() {
  const Held& h = *held_;
  release(h.shard_fd, h.dir / shard_lock_file_name(h.shard_index), true);
  release(h.folder_fd, h.dir / job_lock_file_name(), h.shard_fd < 0);
}

const std::filesystem::path& JobFolderLock::dir() const noexcept { return held_->dir; }
int JobFolderLock::shard_index() const noexcept { return held_->shard_index; }
int JobFolderLock::shard_count() const noexcept { return held_->shard_count; }
const std::optional<std::string>& JobFolderLock::taken_over_from() const noexcept { return held_->taken_over_from; }
bool JobFolderLock::locked_by_files() const noexcept { return held_->by_files; }
StaleTemporaries JobFolderLock::stale_temporaries() const noexcept {
  return held_->shard_count > 1 ? StaleTemporaries::kOfThisMachine : StaleTemporaries::kOfEveryMachine;
}

}  // namespace trivox
