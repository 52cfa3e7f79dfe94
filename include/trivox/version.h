// The library's version (the CMake project version), recorded in every job manifest, and
// what `trivox --version` reports about the build.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace trivox {

std::string_view version() noexcept;

// How this copy of the library was built, for bug reports (docs/CLI.md, "--version").
struct BuildInfo {
  std::string version;     // version()
  std::string commit;      // the git commit the build was configured from; "unknown" outside a checkout
  std::string build_type;  // CMAKE_BUILD_TYPE: Release, Debug, RelWithDebInfo, ...
  std::string compiler;    // the C++ compiler's id and version, e.g. "GNU 12.2.0"
  // Every library the library links, by name, with the version of its headers at compile
  // time; where the library reports the version loaded at run time and it differs, that too
  // ("1.6.39 (1.6.40 at run time)").
  std::vector<std::pair<std::string, std::string>> libraries;
};
BuildInfo build_info();

}  // namespace trivox
