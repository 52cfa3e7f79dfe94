// The memory budget of up-front refusals (trivox/limits.h).
#include "trivox/limits.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <limits>

namespace trivox {

std::optional<std::uint64_t> process_memory_limit_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  std::optional<std::uint64_t> limit;
  if (pages > 0 && page > 0) limit = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    const auto as = static_cast<std::uint64_t>(rl.rlim_cur);
    limit = limit ? std::min(*limit, as) : as;
  }
  return limit;
}

std::optional<std::uint64_t> memory_limit_from_mb(double megabytes) {
  if (megabytes > 0) return static_cast<std::uint64_t>(std::min(megabytes * 1e6, 1.8e19));
  return process_memory_limit_bytes();
}

std::int64_t mesh_triangle_limit() {
  const std::optional<std::uint64_t> memory = process_memory_limit_bytes();
  if (!memory) return kMaxMeshTriangles;
  const auto within = static_cast<std::int64_t>(
      std::min<std::uint64_t>(*memory / 2 / kMeshTrimBytesPerTriangle, static_cast<std::uint64_t>(kMaxMeshTriangles)));
  return std::max<std::int64_t>(within, 1);
}

std::uint64_t input_file_byte_limit() {
  const std::optional<std::uint64_t> memory = process_memory_limit_bytes();
  return memory ? std::max<std::uint64_t>(*memory / 10, 1) : std::numeric_limits<std::uint64_t>::max();
}

}  // namespace trivox
