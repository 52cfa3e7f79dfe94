// Hard kills of the real program: `trivox slice` (30 layers, 2 threads, the manifest rewritten
// after every layer) is sent SIGKILL at 20 moments drawn with a fixed seed - once k layer
// files are on disk (k from 0 to 18), after a further delay of 0 to 20 ms - so that every kill
// lands part way through the job, at any point of a layer's work or of a file's write. After
// each kill the job must be part way (the manifest not complete, layers missing), the
// manifest must read and match what it lists, and every file under a final name must decode;
// `--resume` must then end with every file and the manifest byte-identical to a run that was
// never stopped.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli/cli_run.h"
#include "job/job_fixtures.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/job/manifest.h"
#include "trivox/output/atomic_file.h"
#include "trivox/output/png_io.h"

extern char** environ;

namespace trivox::test {
namespace {

namespace fs = std::filesystem;

constexpr int kLayers = 30;

// The arguments of the job, after the program's name.
std::vector<std::string> slice_words(const fs::path& out) {
  return {"slice",
          (examples_dir() / "scenes" / "quick_start.json").string(),
          "--layers",
          fmt::format("1:{}", kLayers),
          "--min-layers",
          "0",
          "-q",
          "-j",
          "2",
          "--manifest-interval",
          "0",
          "-o",
          out.string()};
}

// The same for run_cli, quoted for the shell.
std::string slice_args(const fs::path& out) {
  std::string args;
  for (const std::string& w : slice_words(out)) {
    if (!args.empty()) args += ' ';
    args += shell_quote(w);
  }
  return args;
}

// Starts trivox with the arguments `words` (no shell), its output thrown away.
pid_t spawn_trivox(const std::vector<std::string>& words) {
  const std::string program = cli_path().string();
  std::vector<char*> argv = {const_cast<char*>(program.c_str())};
  for (const std::string& w : words) argv.push_back(const_cast<char*>(w.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// Layer images under their final names.
int layer_files(const fs::path& out) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::directory_iterator(out, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("slice_", 0) == 0 && it->path().extension() == ".png" && !is_atomic_temporary_name(name)) ++n;
  }
  return n;
}

TEST(CliKill, TwentyKillsAtRandomMomentsEachResumedEndByteIdentical) {
  ScratchDir dir;
  const CliResult ref = run_cli(slice_args(dir.path() / "reference"));
  ASSERT_EQ(ref.exit_code, 0) << ref.err;
  const auto reference = folder_bytes(dir.path() / "reference");
  ASSERT_EQ(reference.size(), static_cast<std::size_t>(kLayers) + 2);  // layers, materials.csv, manifest.json

  std::mt19937 rng(7);
  int resumed_with_kept_layers = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const int after_files = std::uniform_int_distribution<int>(0, 18)(rng);
    const int delay_ms = std::uniform_int_distribution<int>(0, 20)(rng);
    SCOPED_TRACE(fmt::format("trial {}: SIGKILL {} ms after {} layer files", trial, delay_ms, after_files));
    const fs::path out = dir.path() / fmt::format("trial{}", trial);
    const pid_t pid = spawn_trivox(slice_words(out));
    ASSERT_GT(pid, 0);
    bool exited_first = false;
    int status = 0;
    for (;;) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        exited_first = true;
        break;
      }
      std::error_code ec;
      if (fs::exists(out / "manifest.json", ec) && layer_files(out) >= after_files) {
        std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
        ::kill(pid, SIGKILL);
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    if (!exited_first) ::waitpid(pid, &status, 0);
    ASSERT_FALSE(exited_first) << "the job ended before the kill, status " << status;
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;

    // Part way: the manifest is not complete and layers are missing.
    const JobManifest killed = read_manifest(out / "manifest.json");
    EXPECT_EQ(killed.status, JobStatus::kRunning);
    EXPECT_LT(layer_files(out), kLayers);
    EXPECT_LT(killed.files.size(), static_cast<std::size_t>(kLayers));
    // What the manifest lists is on disk as listed (it may lag the files, never lead them).
    for (const ManifestFile& f : killed.files) {
      const FileDigest d = sha256_file(out / f.name);
      EXPECT_EQ(d.sha256, f.sha256) << f.name;
    }
    // Every file under a final name is whole.
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (!e.is_regular_file() || is_atomic_temporary_name(e.path().filename().string())) continue;
      if (e.path().extension() == ".png") {
        EXPECT_NO_THROW(read_png_rgba(e.path())) << e.path();
      }
    }

    const CliResult resumed = run_cli(slice_args(out) + " --resume");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
    if (resumed.out.find("layers were already complete") != std::string::npos) ++resumed_with_kept_layers;
    for (const auto& e : fs::recursive_directory_iterator(out))
      EXPECT_FALSE(is_atomic_temporary_name(e.path().filename().string())) << e.path();
    EXPECT_EQ(folder_bytes(out), reference);
    fs::remove_all(out);
  }
  // Most kills came after some layers were recorded: their resumes kept those layers.
  EXPECT_GE(resumed_with_kept_layers, 10);
}

}  // namespace
}  // namespace trivox::test
