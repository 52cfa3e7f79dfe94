// Runs the built trivox program (TRIVOX_CLI_PATH) through the shell, as a user would, and
// collects its exit code, standard output and standard error. Header-only: the test build
// compiles *_test.cpp files only.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace trivox::test {

struct CliResult {
  int exit_code = -1;  // the shell reports a crash as 128 + the signal number
  std::string out;
  std::string err;
};

inline std::filesystem::path cli_path() { return TRIVOX_CLI_PATH; }
inline std::filesystem::path examples_dir() { return TRIVOX_EXAMPLES_DIR; }

// Single-quotes a path or word for the POSIX shell.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}
inline std::string shell_quote(const std::filesystem::path& p) { return shell_quote(p.string()); }

// A fresh folder under the system's temporary directory, removed with the object.
class ScratchDir {
 public:
  ScratchDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("trivox-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// Runs `trivox <args>` (args already shell-quoted where needed) with `input` on standard input.
// `stdout_redirect`, when given, replaces the capture of standard output (e.g. "/dev/full").
// `launcher`, when given, replaces the program: shell commands to run first ending in a
// `;` ("ulimit -f 16;"), or a program that takes the trivox command as its arguments
// ("timeout": args must then start with its options and name trivox itself).
inline CliResult run_cli(const std::string& args, const std::string& input = {},
                         const std::string& stdout_redirect = {}, const std::string& launcher = {}) {
  ScratchDir dir;
  const auto in = dir.path() / "stdin.txt", out = dir.path() / "stdout.txt", err = dir.path() / "stderr.txt";
  write_text(in, input);
  const bool prefix_only = !launcher.empty() && launcher.back() == ';';
  const std::string program = launcher.empty() ? shell_quote(cli_path())
                              : prefix_only    ? launcher + " " + shell_quote(cli_path())
                                               : launcher;
  const std::string command = program + " " + args + " < " + shell_quote(in) + " > " +
                              (stdout_redirect.empty() ? shell_quote(out) : stdout_redirect) + " 2> " +
                              shell_quote(err);
  const int status = std::system(command.c_str());
  CliResult r;
  r.exit_code = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

// One parsed JSON value per non-empty line of `text` (probe's output).
inline std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

}  // namespace trivox::test
