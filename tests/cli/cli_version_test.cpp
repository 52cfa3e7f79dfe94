// `trivox --version` and `trivox COMMAND --version` (docs/CLI.md, "--version"): the version,
// the git commit, the build type, the compiler and the version of every library it links,
// on standard output with exit 0, whatever else the command line holds.
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_run.h"
#include "trivox/version.h"

namespace trivox::test {
namespace {

struct VersionReport {
  std::map<std::string, std::string> fields;     // "commit" -> "...", ...
  std::map<std::string, std::string> libraries;  // "libpng" -> "1.6.39", ...
  std::string first_line;
};

VersionReport parse_report(const std::string& text) {
  VersionReport r;
  std::istringstream in(text);
  std::getline(in, r.first_line);
  bool in_libraries = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "libraries:") {
      in_libraries = true;
    } else if (in_libraries && line.starts_with("  ")) {
      const auto space = line.find(' ', 2);
      r.libraries[line.substr(2, space - 2)] = space == std::string::npos ? "" : line.substr(space + 1);
    } else if (const auto colon = line.find(": "); colon != std::string::npos) {
      r.fields[line.substr(0, colon)] = line.substr(colon + 2);
    } else {
      ADD_FAILURE() << "unexpected line '" << line << "'";
    }
  }
  return r;
}

// (No std::regex: GCC 12 warns inside it under the sanitizer build's -Werror.)
bool is_commit_hash(const std::string& s) {
  return s.size() == 40 && std::all_of(s.begin(), s.end(), [](char c) {
           return std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f');
         });
}

// "MAJOR.MINOR..." with digits on both sides of the first dot.
bool starts_with_version(const std::string& s) {
  const auto dot = s.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 >= s.size()) return false;
  return std::all_of(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(dot),
                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }) &&
         std::isdigit(static_cast<unsigned char>(s[dot + 1]));
}

// "<compiler id> <version>", the id one of CMake's.
bool is_compiler(const std::string& s) {
  const auto space = s.find(' ');
  if (space == std::string::npos) return false;
  const std::string id = s.substr(0, space), v = s.substr(space + 1);
  const bool known = id == "GNU" || id == "Clang" || id == "AppleClang" || id == "MSVC" || id.starts_with("Intel");
  return known && !v.empty() && std::isdigit(static_cast<unsigned char>(v[0])) &&
         std::all_of(v.begin(), v.end(),
                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.'; });
}

void expect_full_report(const CliResult& run, const std::string& what) {
  EXPECT_EQ(run.exit_code, 0) << what << ": " << run.err;
  EXPECT_EQ(run.err, "") << what;
  VersionReport r = parse_report(run.out);
  EXPECT_EQ(r.first_line, "trivox " + std::string(version())) << what;
  ASSERT_TRUE(r.fields.count("commit")) << what << ":\n" << run.out;
  const std::string& commit = r.fields.at("commit");
  EXPECT_TRUE(commit == "unknown" || is_commit_hash(commit)) << commit;
  EXPECT_EQ(r.fields.count("build type"), 1u) << what;
  EXPECT_FALSE(r.fields["build type"].empty());
  EXPECT_TRUE(is_compiler(r.fields["compiler"])) << r.fields["compiler"];
  for (const char* name : {"CLI11", "fmt", "Highway", "libpng", "libtiff", "muParser", "nlohmann-json", "oneTBB",
                           "OpenSSL", "pugixml", "zlib"}) {
    ASSERT_TRUE(r.libraries.count(name)) << what << ": no " << name << " in\n" << run.out;
    EXPECT_TRUE(starts_with_version(r.libraries.at(name))) << name << ": " << r.libraries.at(name);
  }
  // The version of the headers the program was compiled against, as this test sees them.
  EXPECT_TRUE(r.libraries["libpng"].starts_with(PNG_LIBPNG_VER_STRING)) << r.libraries["libpng"];
  EXPECT_TRUE(r.libraries["fmt"].starts_with(fmt::format("{}.{}.", FMT_VERSION / 10000, FMT_VERSION / 100 % 100)))
      << r.libraries["fmt"];
}

TEST(CliVersion, TheProgramReportsVersionCommitBuildCompilerAndLibraries) {
  expect_full_report(run_cli("--version"), "trivox --version");
}

TEST(CliVersion, EverySubcommandTakesVersionEvenWithoutItsRequiredArguments) {
  for (const char* command : {"init", "slice", "validate", "merge", "verify", "info", "probe", "build"})
    expect_full_report(run_cli(fmt::format("{} --version", command)), fmt::format("trivox {} --version", command));
  // With other options around it, too: nothing is read or written.
  expect_full_report(run_cli("slice missing.json -o /nonexistent/out --version"), "slice ... --version");
}

// "SIMD: avx2 (available: avx512, avx2, sse4, baseline)": the target in use and the list.
TEST(CliVersion, ReportsTheSimdTargetAndTrivoxSimdChoosesIt) {
  ::unsetenv("TRIVOX_SIMD");
  const VersionReport best = parse_report(run_cli("--version").out);
  ASSERT_TRUE(best.fields.count("SIMD")) << "no SIMD line";
  const std::string& line = best.fields.at("SIMD");
  const auto open = line.find(" (available: ");
  ASSERT_NE(open, std::string::npos) << line;
  ASSERT_TRUE(line.ends_with(")")) << line;
  std::vector<std::string> available;
  std::istringstream list(line.substr(open + 13, line.size() - open - 14));
  for (std::string name; std::getline(list, name, ',');)
    available.push_back(name.substr(name.starts_with(" ") ? 1 : 0));
  ASSERT_FALSE(available.empty()) << line;
  EXPECT_EQ(line.substr(0, open), available.front()) << "the best target is used by default";
  for (const std::string& target : available) {
    ::setenv("TRIVOX_SIMD", target.c_str(), 1);
    const CliResult run = run_cli("--version");
    EXPECT_EQ(run.exit_code, 0) << target << ": " << run.err;
    EXPECT_TRUE(parse_report(run.out).fields["SIMD"].starts_with(target + " (")) << target << ":\n" << run.out;
  }
  ::setenv("TRIVOX_SIMD", "avx3", 1);
  const CliResult bad = run_cli("--version");
  ::unsetenv("TRIVOX_SIMD");
  EXPECT_EQ(bad.exit_code, 3) << bad.err;
  EXPECT_NE(bad.err.find("TRIVOX_SIMD: unknown target 'avx3' (expected one of: "), std::string::npos) << bad.err;
}

TEST(CliVersion, TheHelpListsTheFlag) {
  const CliResult r = run_cli("slice --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--version"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace trivox::test
