#include "trivox/job/job_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
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

// "process 1234 on host h, started T" from "pid=1234 host=h started=T"; the line itself when
// it is not in that form (written by hand, or truncated).
std::string holder_text(const std::string& line) {
  std::string pid, host, started;
  std::size_t at = 0;
  while (at < line.size()) {
    const std::size_t end = std::min(line.find(' ', at), line.size());
    const std::string word = line.substr(at, end - at);
    if (word.starts_with("pid=")) pid = word.substr(4);
    if (word.starts_with("host=")) host = word.substr(5);
    if (word.starts_with("started=")) started = word.substr(8);
    at = end + 1;
  }
  if (pid.empty()) return line.empty() ? std::string("a process that has not yet said who it is") : "'" + line + "'";
  return fmt::format("process {}{}{}", pid, host.empty() ? "" : " on host " + host,
                     started.empty() ? "" : ", started " + started);
}

std::string this_holder_line() {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) std::strcpy(host, "unknown");
  const auto now = std::chrono::time_point_cast<std::chrono::seconds>(std::chrono::system_clock::now());
  return fmt::format("pid={} host={} started={:%Y-%m-%dT%H:%M:%SZ}\n", ::getpid(), host, now);
}

// Takes a flock of `mode` (LOCK_EX or LOCK_SH) on `path` without waiting. Returns the file
// descriptor, or -1 when another process holds a conflicting lock. A lock file is removed by
// the job that releases it last, so the file locked must still be the one under `path`:
// otherwise the lock was taken on a file just removed, and the loop opens the new one.
int try_lock(const std::filesystem::path& path, int mode) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw IoError(fmt::format("{}: cannot create the lock file: {}", path.string(), errno_text(errno)));
    if (::flock(fd, mode | LOCK_NB) != 0) {
      const int error = errno;
      ::close(fd);
      if (error == EWOULDBLOCK) return -1;
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

// The shards of `dir` whose lock is held now, as "shard I (process ...)".
std::vector<std::string> running_shards(const std::filesystem::path& dir) {
  std::vector<std::string> shards;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(".trivox-shard-") || !name.ends_with(".lock")) continue;
    const int fd = ::open(entry.path().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_SH | LOCK_NB) != 0)
      shards.push_back(
          fmt::format("shard {} ({})", name.substr(14, name.size() - 14 - 5), holder_text(holder_line(fd))));
    ::close(fd);
  }
  return shards;
}

[[noreturn]] void refuse(const std::filesystem::path& dir, const std::filesystem::path& lock_file,
                         const std::string& holders) {
  throw Error(fmt::format(
      "{}: another trivox job is writing into this folder ({}; lock file {}): wait for it to end, or slice into "
      "another folder",
      dir.string(), holders, lock_file.string()));
}

}  // namespace

std::string job_lock_file_name() { return ".trivox.lock"; }
std::string shard_lock_file_name(int shard_index) { return fmt::format(".trivox-shard-{}.lock", shard_index); }

JobFolderLock::JobFolderLock(const std::filesystem::path& dir, int shard_index, int shard_count)
    : dir_(dir), shard_index_(shard_index), shard_count_(shard_count) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create output folder: {}", dir_.string(), ec.message()));
  const std::filesystem::path folder_lock = dir_ / job_lock_file_name();
  const bool sharded = shard_count_ > 1;
  folder_fd_ = try_lock(folder_lock, sharded ? LOCK_SH : LOCK_EX);
  if (folder_fd_ < 0) {
    // A whole job holds it (its line is in the file), or running shards hold it shared.
    const std::vector<std::string> shards = running_shards(dir_);
    std::string holders = shards.empty() ? holder_text(holder_line(folder_lock)) : std::string();
    for (const std::string& s : shards) holders += (holders.empty() ? "" : ", ") + s;
    refuse(dir_, folder_lock, holders);
  }
  if (!sharded) {
    const std::string previous = holder_line(folder_fd_);
    if (!previous.empty()) taken_over_from_ = previous;
    try {
      line_bytes_ = write_holder(folder_fd_, folder_lock);
    } catch (...) {
      release(folder_fd_, folder_lock, true);
      throw;
    }
    return;
  }
  const std::filesystem::path shard_lock = dir_ / shard_lock_file_name(shard_index_);
  try {
    shard_fd_ = try_lock(shard_lock, LOCK_EX);
  } catch (...) {
    release(folder_fd_, folder_lock, false);
    throw;
  }
  if (shard_fd_ < 0) {
    release(folder_fd_, folder_lock, false);
    refuse(dir_, shard_lock, holder_text(holder_line(shard_lock)));
  }
  const std::string previous = holder_line(shard_fd_);
  if (!previous.empty()) taken_over_from_ = previous;
  try {
    line_bytes_ = write_holder(shard_fd_, shard_lock);
  } catch (...) {
    release(shard_fd_, shard_lock, true);
    release(folder_fd_, folder_lock, false);
    throw;
  }
}

bool JobFolderLock::reserve_bytes(std::uint64_t bytes) {
  const int fd = shard_fd_ >= 0 ? shard_fd_ : folder_fd_;
  if (bytes <= reserved_) return true;
  // Blocks actually allocated (not a sparse extension), so that freeing them makes room.
  if (::posix_fallocate(fd, static_cast<off_t>(line_bytes_), static_cast<off_t>(bytes)) != 0) return false;
  reserved_ = bytes;
  return true;
}

void JobFolderLock::release_reserve() noexcept {
  const int fd = shard_fd_ >= 0 ? shard_fd_ : folder_fd_;
  if (reserved_ > 0 && ::ftruncate(fd, static_cast<off_t>(line_bytes_)) == 0) reserved_ = 0;
}

JobFolderLock::~JobFolderLock() {
  release(shard_fd_, dir_ / shard_lock_file_name(shard_index_), true);
  release(folder_fd_, dir_ / job_lock_file_name(), shard_fd_ < 0);
}

}  // namespace trivox
