// The trivox program: registers the subcommands (commands.h) and is the only place where
// errors become messages on standard error and exit codes (cli_errors.h, docs/CLI.md).
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <system_error>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_errors.h"
#include "commands.h"
#include "trivox/error.h"
#include "trivox/simd.h"
#include "trivox/version.h"

namespace {

// What --version prints (docs/CLI.md, "--version"): enough to identify the build in a bug
// report. The program adds CLI11, which only it links, to the library's list.
std::string version_text() {
  trivox::BuildInfo b = trivox::build_info();
  b.libraries.emplace_back("CLI11",
                           fmt::format("{}.{}.{}", CLI11_VERSION_MAJOR, CLI11_VERSION_MINOR, CLI11_VERSION_PATCH));
  std::sort(b.libraries.begin(), b.libraries.end(), [](const auto& x, const auto& y) {
    return std::lexicographical_compare(x.first.begin(), x.first.end(), y.first.begin(), y.first.end(),
                                        [](char a, char c) { return std::tolower(a) < std::tolower(c); });
  });
  std::string text = fmt::format("trivox {}\ncommit: {}\nbuild type: {}\ncompiler: {}\nlibraries:", b.version, b.commit,
                                 b.build_type, b.compiler);
  for (const auto& [name, version] : b.libraries) text += fmt::format("\n  {} {}", name, version);
  // The evaluation kernels' SIMD target in use and those this processor could run.
  text += fmt::format("\nSIMD: {} (available: {})", trivox::simd_target(), fmt::join(trivox::simd_targets(), ", "));
  return text;
}

// A message with every run of more than 4096 bytes without a blank (a name the input made
// that long, which the library echoed) cut as trivox::shown_name cuts names: one readable line
// whatever the input holds. Paths stay whole (PATH_MAX is 4096).
std::string with_long_words_cut(std::string_view message) {
  constexpr std::size_t kLongest = 4096;
  std::string out;
  std::size_t at = 0;
  while (at < message.size()) {
    const std::size_t end = std::min(message.find(' ', at), message.size());
    const std::string_view word = message.substr(at, end - at);
    if (word.size() > kLongest) {
      const auto continuation = [](char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; };
      std::size_t cut = 80;
      while (cut > 0 && continuation(word[cut])) --cut;
      const auto characters = std::count_if(word.begin(), word.end(), [&](char c) { return !continuation(c); });
      out += fmt::format("{}... ({} characters)", word.substr(0, cut), characters);
    } else {
      out += word;
    }
    if (end < message.size()) out += ' ';
    at = end + 1;
  }
  return out;
}

int fail(trivox::cli::ExitCode code, std::string_view kind, std::string_view message) {
  std::fflush(stdout);  // keep what was printed before the error ahead of it in a shared log
  fmt::print(stderr, "trivox: {}: {}\n", kind, with_long_words_cut(message));
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace trivox::cli;
  // A reader that goes away (`trivox probe ... | head -1`) must not kill the program by
  // SIGPIPE: writes then fail with EPIPE, and the program ends with exit 4 and no message
  // (docs/CLI.md, "Exit codes").
  std::signal(SIGPIPE, SIG_IGN);
  try {
    CLI::App app{
        "trivox: slices functionally graded material objects made of trivariate "
        "B-spline and NURBS volumes.",
        "trivox"};
    app.require_subcommand(1);
    // TRIVOX_SIMD restricts the kernels to one SIMD target (docs/CLI.md, "Environment").
    if (const char* simd = std::getenv("TRIVOX_SIMD"); simd != nullptr && *simd != '\0') trivox::use_simd_target(simd);
    for (const AddCommand add : kCommands) add(app);
    // --version on the program and on every subcommand (`trivox slice --version` too).
    const char* version_help = "Print the version, git commit, build type, compiler and libraries, and exit";
    app.set_version_flag("--version", version_text, version_help);
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
      sub->set_version_flag("--version", version_text, version_help);
    // CLI11 reports a misspelt command as "A subcommand is required"; name it instead.
    if (argc > 1 && argv[1][0] != '-') {
      std::string names;
      bool known = false;
      for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
        known = known || sub->get_name() == argv[1];
        names += (names.empty() ? "" : ", ") + sub->get_name();
      }
      if (!known) throw UsageError(fmt::format("unknown command '{}' (the commands are {})", argv[1], names));
    }
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      // --help and --version are ParseErrors too; CLI11 prints them and reports 0.
      if (app.exit(e) != 0) return kExitUsage;
    }
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
      if (errno == EPIPE) return kExitIo;  // the reader has gone: end quietly (below)
      return fail(kExitIo, "error", fmt::format("cannot write to standard output: {}", std::strerror(errno)));
    }
    return kExitOk;
  } catch (const UsageError& e) {
    const int code = fail(kExitUsage, "usage error", e.what());
    std::fputs("Run with --help for more information.\n", stderr);
    return code;
  } catch (const InterruptedError& e) {
    return fail(kExitInterrupted, "interrupted", e.what());
  } catch (const trivox::CancelledError& e) {  // Ctrl-C before the job's folder was touched
    return fail(kExitInterrupted, "interrupted", fmt::format("{}; nothing was written", e.what()));
  } catch (const trivox::EmptyResultError& e) {  // a stack without the object (--allow-empty accepts it)
    return fail(kExitEmpty, "error", e.what());
  } catch (const CorruptOutputError& e) {
    return fail(kExitCorrupt, "verify failed", e.what());
  } catch (const trivox::IoError& e) {
    return fail(kExitIo, "error", e.what());
  } catch (const trivox::UnsupportedError& e) {  // a valid file using a feature trivox lacks
    return fail(kExitInput, "unsupported", e.what());
  } catch (const trivox::Error& e) {  // InputError, ModelError, settings the job cannot take
    return fail(kExitInput, "error", e.what());
  } catch (const std::system_error& e) {                     // failed writes (fmt), filesystem errors
    if (e.code() == std::errc::broken_pipe) return kExitIo;  // the reader of a pipe has gone
    return fail(kExitIo, "error", e.what());
  } catch (const std::bad_alloc&) {
    return fail(kExitInternal, "internal error", "out of memory");
  } catch (const std::exception& e) {
    return fail(kExitInternal, "internal error", e.what());
  } catch (...) {
    return fail(kExitInternal, "internal error", "unknown exception");
  }
}
