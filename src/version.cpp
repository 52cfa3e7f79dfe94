#include "trivox/version.h"

#include <oneapi/tbb/version.h>
#include <openssl/crypto.h>
#include <openssl/opensslv.h>
#include <png.h>
#include <tiffvers.h>
#include <zlib.h>

#include <fmt/format.h>
#include <hwy/highway.h>
#include <muParserDef.h>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>

// Set by src/CMakeLists.txt on this file alone (so that a new commit recompiles nothing else).
#ifndef TRIVOX_GIT_COMMIT
#define TRIVOX_GIT_COMMIT "unknown"
#endif
#ifndef TRIVOX_BUILD_TYPE
#define TRIVOX_BUILD_TYPE "unknown"
#endif
#ifndef TRIVOX_COMPILER
#define TRIVOX_COMPILER "unknown"
#endif

namespace trivox {

namespace {

// The compile-time version, and the run-time one when the loaded library reports another.
std::string with_runtime(std::string compiled, const char* runtime) {
  if (runtime == nullptr || compiled == runtime) return compiled;
  return fmt::format("{} ({} at run time)", compiled, runtime);
}

}  // namespace

std::string_view version() noexcept { return TRIVOX_VERSION_STRING; }

BuildInfo build_info() {
  BuildInfo b;
  b.version = std::string(version());
  b.commit = TRIVOX_GIT_COMMIT;
  b.build_type = TRIVOX_BUILD_TYPE;
  b.compiler = TRIVOX_COMPILER;
  // muParser's version string carries a build note ("2.3.3 (Release)"): the number alone.
  std::string muparser = mu::ParserVersion;
  muparser = muparser.substr(0, muparser.find(' '));
  b.libraries = {
      {"fmt", fmt::format("{}.{}.{}", FMT_VERSION / 10000, FMT_VERSION / 100 % 100, FMT_VERSION % 100)},
      {"Highway", fmt::format("{}.{}.{}", HWY_MAJOR, HWY_MINOR, HWY_PATCH)},
      {"libpng", with_runtime(PNG_LIBPNG_VER_STRING, png_get_libpng_ver(nullptr))},
      {"libtiff", fmt::format("{}.{}.{}", TIFFLIB_MAJOR_VERSION, TIFFLIB_MINOR_VERSION, TIFFLIB_MICRO_VERSION)},
      {"muParser", muparser},
      {"nlohmann-json",
       fmt::format("{}.{}.{}", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH)},
      {"oneTBB", with_runtime(TBB_VERSION_STRING, TBB_runtime_version())},
      {"OpenSSL", with_runtime(OPENSSL_VERSION_STR, OpenSSL_version(OPENSSL_VERSION_STRING))},
      {"pugixml", fmt::format("{}.{}", PUGIXML_VERSION / 1000, PUGIXML_VERSION / 10 % 100)},
      {"zlib", with_runtime(ZLIB_VERSION, zlibVersion())},
  };
  return b;
}

}  // namespace trivox
