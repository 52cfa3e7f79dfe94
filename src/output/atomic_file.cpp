#include "trivox/output/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox {

namespace {

std::string errno_text(int error_number) { return std::error_code(error_number, std::generic_category()).message(); }

constexpr std::string_view kTempMarker = ".tmp-";

// The characters machine_name() keeps.
bool host_character(char c) noexcept {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_';
}

}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& target) : target_(target) {
  if (target.filename().empty()) throw IoError(fmt::format("{}: not a file name", target.string()));
  static std::atomic<unsigned> counter{0};
  const std::string base = target.filename().string();
  for (int attempt = 0; attempt < 100; ++attempt) {
    path_ = target.parent_path() /
            fmt::format("{}{}{}-{}@{}", base, kTempMarker, static_cast<long>(::getpid()), counter++, machine_name());
    const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw IoError(fmt::format("{}: cannot create {}: {}", target.string(), path_.string(), errno_text(errno)));
    }
    file_ = ::fdopen(fd, "wb");
    if (file_ == nullptr) {
      const int error_number = errno;
      ::close(fd);
      ::unlink(path_.c_str());
      throw IoError(fmt::format("{}: cannot open {}: {}", target.string(), path_.string(), errno_text(error_number)));
    }
    return;
  }
  throw IoError(fmt::format("{}: no free temporary name beside it", target.string()));
}

AtomicFile::~AtomicFile() {
  if (file_ != nullptr) std::fclose(file_);
  if (!committed_) ::unlink(path_.c_str());
}

void AtomicFile::write(std::string_view bytes) {
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) fail("cannot write", errno);
}

void AtomicFile::commit() {
  if (std::fflush(file_) != 0) fail("cannot write", errno);
  if (::fsync(::fileno(file_)) != 0) fail("cannot sync", errno);
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0) fail("cannot close", errno);
  if (std::rename(path_.c_str(), target_.c_str()) != 0) fail("cannot rename", errno);
  committed_ = true;
}

void AtomicFile::fail(const char* what, int error_number) const {
  throw IoError(fmt::format("{}: {} {}: {}", target_.string(), what, path_.string(), errno_text(error_number)));
}

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes) {
  AtomicFile file(path);
  file.write(bytes);
  file.commit();
}

std::string machine_name() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "unknown";
  std::string name(host, std::min<std::size_t>(std::strlen(host), 64));
  for (char& c : name)
    if (!host_character(c)) c = '_';
  return name;
}

bool process_runs_here(long pid) noexcept {
  if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

namespace {

// The host part of a temporary's name ("@<host>" after the digits); empty when it has none.
std::string_view host_of_temporary(std::string_view name) noexcept {
  const std::size_t at = name.rfind('@');
  return at == std::string_view::npos ? std::string_view() : name.substr(at + 1);
}

}  // namespace

bool is_atomic_temporary_name(std::string_view name) noexcept {
  // "<name>.tmp-<pid>-<n>", then "@<host>" (machine_name's characters) since hosts are named.
  if (const std::size_t at = name.rfind('@'); at != std::string_view::npos) {
    const std::string_view host = name.substr(at + 1);
    if (host.empty() || !std::all_of(host.begin(), host.end(), host_character)) return false;
    name = name.substr(0, at);
  }
  const std::size_t at = name.rfind(kTempMarker);
  if (at == std::string_view::npos || at == 0) return false;
  const std::string_view rest = name.substr(at + kTempMarker.size());
  const std::size_t dash = rest.find('-');
  if (dash == std::string_view::npos || dash == 0 || dash + 1 == rest.size()) return false;
  for (std::size_t i = 0; i < rest.size(); ++i)
    if (i != dash && !std::isdigit(static_cast<unsigned char>(rest[i]))) return false;
  return true;
}

namespace {

// Whether the pid in a temporary's name ("<name>.tmp-<pid>-<n>[@<host>]") is a process that
// runs now on this machine, other than this one (whose own temporaries are stale when a job
// starts).
bool written_by_a_running_process(std::string_view name) noexcept {
  const std::size_t at = name.rfind(kTempMarker) + kTempMarker.size();
  long pid = 0;
  for (std::size_t i = at; i < name.size() && name[i] != '-' && pid < 1'000'000'000; ++i)
    pid = pid * 10 + (name[i] - '0');
  if (pid <= 0 || pid > 1'000'000'000 || pid == static_cast<long>(::getpid())) return false;
  return process_runs_here(pid);
}

}  // namespace

int remove_stale_temporaries(const std::filesystem::path& dir, StaleTemporaries scope) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return 0;
  const std::string here = machine_name();
  const auto stale_one = [&](const std::string& name) {
    if (!is_atomic_temporary_name(name)) return false;
    const std::string_view host = host_of_temporary(name);
    if (!host.empty() && host != here) return scope == StaleTemporaries::kOfEveryMachine;
    return !written_by_a_running_process(name);
  };
  std::vector<std::filesystem::path> stale;
  for (auto it = std::filesystem::recursive_directory_iterator(dir, ec); !ec && it != std::filesystem::end(it);
       it.increment(ec))
    if (it->is_regular_file(ec) && stale_one(it->path().filename().string())) stale.push_back(it->path());
  if (ec) throw IoError(fmt::format("{}: cannot list: {}", dir.string(), ec.message()));
  for (const auto& p : stale) {
    std::filesystem::remove(p, ec);
    if (ec) throw IoError(fmt::format("{}: cannot remove a stale temporary file: {}", p.string(), ec.message()));
  }
  return static_cast<int>(stale.size());
}

}  // namespace trivox
