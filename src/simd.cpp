#include "trivox/simd.h"

#include <hwy/highway.h>
#include <hwy/targets.h>

#include <cstdint>

#include "trivox/error.h"

namespace trivox {

namespace {

struct NamedTarget {
  const char* name;
  std::int64_t bits;  // Highway's target bit
};

// Best first. "baseline" is what the compiler may assume of every processor the build runs
// on: x86-64's SSE2 (Highway's SCALAR target) in the default build, more under TRIVOX_NATIVE.
constexpr NamedTarget kTargets[] = {
    {"avx512", HWY_AVX3},
    {"avx2", HWY_AVX2},
    {"sse4", HWY_SSE4},
    {"baseline", HWY_STATIC_TARGET},
};

// The compiled targets this processor runs, as bits (before any restriction).
std::int64_t runnable() {
  hwy::SetSupportedTargetsForTest(0);  // the processor's own list; restored by the caller
  return hwy::SupportedTargets() & HWY_TARGETS;
}

std::int64_t restriction = 0;  // 0: none

}  // namespace

std::vector<std::string> simd_targets() {
  const std::int64_t bits = runnable();
  hwy::SetSupportedTargetsForTest(restriction);
  std::vector<std::string> out;
  std::int64_t listed = 0;
  for (const NamedTarget& t : kTargets)
    if ((bits & t.bits) != 0 && (listed & t.bits) == 0) {
      out.emplace_back(t.name);
      listed |= t.bits;
    }
  return out;
}

std::string simd_target() {
  // Highway tries targets from the lowest bit, the best; the first one both compiled and
  // supported (under the restriction) is the one dispatched to.
  const std::int64_t bits = hwy::SupportedTargets() & HWY_TARGETS;
  const std::int64_t best = bits & -bits;
  for (const NamedTarget& t : kTargets)
    if (t.bits == best) return t.name;
  return hwy::TargetName(best);
}

void use_simd_target(std::string_view name) {
  if (name == "best") {
    restriction = 0;
    hwy::SetSupportedTargetsForTest(0);
    return;
  }
  const std::vector<std::string> names = simd_targets();
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  for (const NamedTarget& t : kTargets)
    if (name == t.name) {
      bool runs = false;
      for (const std::string& n : names) runs = runs || n == name;
      if (!runs)
        throw InputError("TRIVOX_SIMD", 0, "",
                         "'" + std::string(name) +
                             "' is not available on this processor in this build (available: " + list + ", best)");
      restriction = t.bits;
      hwy::SetSupportedTargetsForTest(restriction);
      return;
    }
  throw InputError("TRIVOX_SIMD", 0, "",
                   "unknown target '" + std::string(name) + "' (expected one of: " + list + ", best)");
}

}  // namespace trivox
