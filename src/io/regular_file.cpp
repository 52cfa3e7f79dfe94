// Input files checked by kind before they are read (trivox/io/detail/regular_file.h).
#include "trivox/io/detail/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

#include <fmt/format.h>

#include "trivox/cancel.h"
#include "trivox/error.h"

namespace trivox {

namespace {

std::optional<std::string> kind_problem(mode_t mode) {
  if (S_ISREG(mode)) return std::nullopt;
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string errno_text(int e) { return std::error_code(e, std::generic_category()).message(); }

// Closes the descriptor on every way out.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::optional<std::string> not_a_regular_file(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return errno == ENOENT || errno == ENOTDIR ? std::string("no file")
                                               : fmt::format("a path that cannot be examined ({})", errno_text(errno));
  return kind_problem(st.st_mode);
}

std::string read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes,
                              const std::atomic<bool>* stop) {
  Descriptor d;
  d.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (d.fd < 0) throw IoError(fmt::format("{}: cannot open: {}", path.string(), errno_text(errno)));
  struct stat st {};
  if (::fstat(d.fd, &st) != 0) throw IoError(fmt::format("{}: cannot read: {}", path.string(), errno_text(errno)));
  if (const auto problem = kind_problem(st.st_mode))
    throw IoError(fmt::format("{} is {}, not a regular file", path.string(), *problem));
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (st.st_size < 0 || size > max_bytes)
    throw IoError(fmt::format("{} has {} bytes, more than the {} it may have", path.string(), st.st_size, max_bytes));
  std::string bytes(static_cast<std::size_t>(size), '\0');
  std::size_t at = 0;
  // In pieces, so that a stop is seen within one piece's read even from a slow file system.
  constexpr std::size_t kPiece = std::size_t{16} << 20;
  while (at < bytes.size()) {
    throw_if_stopped(stop, "reading an input file");
    const ssize_t n = ::read(d.fd, bytes.data() + at, std::min(kPiece, bytes.size() - at));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(fmt::format("{}: cannot read: {}", path.string(), errno_text(errno)));
    if (n == 0) break;
    at += static_cast<std::size_t>(n);
  }
  char extra = 0;
  ssize_t more = 0;
  do more = ::read(d.fd, &extra, 1);
  while (more < 0 && errno == EINTR);
  if (at != bytes.size() || more != 0)
    throw IoError(fmt::format("{} changed size while it was read ({} bytes when opened)", path.string(), size));
  return bytes;
}

}  // namespace trivox
