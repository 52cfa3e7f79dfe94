// Runs the built trivox program (TRIVOX_CLI_PATH) through the shell, as a user would, and
// collects its exit code, standard output and standard error. Header-only: the test build
// compiles *_test.cpp files only.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
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

// Starts `trivox <args>` without a shell, as a shell would (SIGINT, SIGTERM and SIGPIPE at
// their default actions), its standard input and output the descriptors given (-1: none
// given, /dev/null) and its standard error written to `err`. `close_in_child` is closed in the
// child (the other end of a pipe). Returns the child's pid, for waitpid; -1 when fork fails.
inline pid_t start_cli(const std::vector<std::string>& args, int in_fd, int out_fd, const std::filesystem::path& err,
                       int close_in_child = -1) {
  const std::string program = cli_path().string();  // before fork: nothing allocates after it
  std::vector<char*> argv{const_cast<char*>(program.c_str())};
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child != 0) return child;
  for (int sig : {SIGINT, SIGTERM, SIGPIPE}) ::signal(sig, SIG_DFL);
  if (close_in_child >= 0) ::close(close_in_child);
  const int null_fd = ::open("/dev/null", O_RDWR);
  ::dup2(in_fd >= 0 ? in_fd : null_fd, STDIN_FILENO);
  ::dup2(out_fd >= 0 ? out_fd : null_fd, STDOUT_FILENO);
  ::dup2(::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), STDERR_FILENO);
  ::execv(argv[0], argv.data());
  ::_exit(127);
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
