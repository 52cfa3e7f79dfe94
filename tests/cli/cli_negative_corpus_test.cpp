// The negative corpus (tests/data/negative/manifest.tsv): bad inputs run through the real
// trivox program, one CTest entry per row. Each must end with its documented exit code
// (docs/CLI.md), a message on standard error holding the row's texts (the file and the
// field, line or option at fault, and the rule), within 2 s and 256 MB, leaving nothing in
// the output folder. The program runs in a child process (no shell) and its peak memory is
// wait4's ru_maxrss. Linux keeps the child's high-water mark across exec, so the figure also
// counts the test process's pages the forked child held before exec: an upper bound, larger
// under AddressSanitizer. RLIMIT_AS cannot be used instead: AddressSanitizer reserves
// terabytes of address space.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli_run.h"

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxSeconds = 2.0;
constexpr long kMaxRssKib = 256 * 1024;

fs::path data_dir() { return TRIVOX_TEST_DATA_DIR; }

struct NegativeCase {
  std::string name;
  int exit_code = -1;
  std::string command;                // after `trivox`, words separated by blanks
  std::vector<std::string> messages;  // each must appear in standard error
  int manifest_line = 0;
};

// Test names carry the case name; gtest would print the struct's bytes otherwise.
void PrintTo(const NegativeCase& c, std::ostream* os) { *os << c.name; }

// Rows: name, exit code, command, then one or more message texts, separated by tabs.
// Blank lines and lines starting with '#' are comments.
std::vector<NegativeCase> read_manifest() {
  std::vector<NegativeCase> cases;
  std::ifstream in(data_dir() / "negative" / "manifest.tsv");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string f; std::getline(row, f, '\t');) fields.push_back(f);
    NegativeCase c;
    c.manifest_line = number;
    if (fields.size() >= 4) {
      c.name = fields[0];
      c.exit_code = std::stoi(fields[1]);
      c.command = fields[2];
      c.messages.assign(fields.begin() + 3, fields.end());
    } else {
      c.name = "malformed_manifest_line_" + std::to_string(number);
    }
    cases.push_back(std::move(c));
  }
  return cases;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

struct MeasuredRun {
  int exit_code = -1;  // -1 when the program died from a signal
  int signal = 0;
  double seconds = 0;
  long max_rss_kib = 0;
  std::string err;
};

// Runs trivox with `args` (no shell), standard input from /dev/null, output to files.
MeasuredRun run_measured(const std::vector<std::string>& args, const fs::path& scratch) {
  const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  std::vector<std::string> argv_text{cli_path().string()};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);

  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in_fd = ::open("/dev/null", O_RDONLY);
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in_fd < 0 || out_fd < 0 || err_fd < 0) ::_exit(126);
    ::dup2(in_fd, 0);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    const rlimit cpu{20, 20};  // a runaway case ends instead of hanging the suite
    ::setrlimit(RLIMIT_CPU, &cpu);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  MeasuredRun r;
  int status = 0;
  rusage usage{};
  if (pid > 0 && ::wait4(pid, &status, 0, &usage) == pid) {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.max_rss_kib = usage.ru_maxrss;
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  }
  r.err = read_text(err);
  return r;
}

class NegativeCorpus : public ::testing::TestWithParam<NegativeCase> {};

TEST_P(NegativeCorpus, ExitsWithItsCodeAndMessageQuicklyLeavingNoOutput) {
  const NegativeCase& c = GetParam();
  ASSERT_FALSE(c.messages.empty()) << "manifest.tsv line " << c.manifest_line
                                   << " needs: name, exit code, command, message texts (tab-separated)";
  ScratchDir scratch;
  const fs::path out = scratch.path() / "out";  // never created by the test
  const fs::path file = scratch.path() / "a_file";
  write_text(file, "not a folder\n");
  auto expand = [&](std::string s) {
    s = replace_all(s, "{negative}", (data_dir() / "negative").string());
    s = replace_all(s, "{malformed}", (data_dir() / "malformed").string());
    s = replace_all(s, "{models}", (data_dir() / "models").string());
    s = replace_all(s, "{out}", out.string());
    return replace_all(s, "{file}", file.string());
  };
  std::vector<std::string> args;
  std::istringstream words(expand(c.command));
  for (std::string w; words >> w;) args.push_back(w);

  const MeasuredRun r = run_measured(args, scratch.path());
  const std::string where = "manifest.tsv line " + std::to_string(c.manifest_line) + ": trivox " + c.command;
  EXPECT_EQ(r.signal, 0) << where << " died from signal " << r.signal << "\n" << r.err;
  EXPECT_EQ(r.exit_code, c.exit_code) << where << "\n" << r.err;
  for (const std::string& m : c.messages)
    EXPECT_NE(r.err.find(expand(m)), std::string::npos) << where << ": '" << expand(m) << "' not in:\n" << r.err;
  // In the XML/JSON report (--gtest_output), for docs/RELIABILITY.md.
  RecordProperty("seconds", std::to_string(r.seconds));
  RecordProperty("max_rss_kib", std::to_string(r.max_rss_kib));
  EXPECT_LE(r.seconds, kMaxSeconds) << where;
  EXPECT_LE(r.max_rss_kib, kMaxRssKib) << where << ": peak memory " << r.max_rss_kib << " KiB";
  if (fs::exists(out)) {
    EXPECT_TRUE(fs::is_directory(out) && fs::is_empty(out)) << where << ": output left behind in " << out;
  }
}

std::string case_name(const ::testing::TestParamInfo<NegativeCase>& info) {
  std::string name = info.param.name;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Manifest, NegativeCorpus, ::testing::ValuesIn(read_manifest()), case_name);

TEST(NegativeCorpusManifest, HoldsAtLeast40CasesAndNamesEveryCorpusFile) {
  const std::vector<NegativeCase> cases = read_manifest();
  EXPECT_GE(cases.size(), 40u);
  // Every input file beside the manifest is used by some row, so none sits there unchecked.
  for (const auto& e : fs::directory_iterator(data_dir() / "negative")) {
    const std::string name = e.path().filename().string();
    if (name == "manifest.tsv" || name == "ok_box.json") continue;
    bool used = false;
    for (const NegativeCase& c : cases) used = used || c.command.find("{negative}/" + name) != std::string::npos;
    EXPECT_TRUE(used) << name << " is in tests/data/negative but no manifest row uses it";
  }
}

}  // namespace
}  // namespace trivox::test
