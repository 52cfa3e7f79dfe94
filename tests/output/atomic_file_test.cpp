// Temporaries of AtomicFile (include/trivox/output/atomic_file.h) name their process and their
// machine, and a resume judges another machine's by the scope it is given, never by a pid that
// means nothing here.
#include "trivox/output/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace trivox {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFile, ATemporaryNamesItsProcessAndMachine) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-atomic-test-{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    AtomicFile file(dir / "slice_00001.png");
    const std::string name = file.temporary().filename().string();
    EXPECT_EQ(name.rfind(fmt::format("slice_00001.png.tmp-{}-", ::getpid()), 0), 0u) << name;
    EXPECT_TRUE(name.ends_with(fmt::format("@{}", machine_name()))) << name;
    EXPECT_TRUE(is_atomic_temporary_name(name)) << name;
  }
  EXPECT_TRUE(fs::is_empty(dir));  // never committed: removed
  fs::remove_all(dir);
}

TEST(AtomicFile, TemporaryNamesOfEveryReleaseAreRecognisedAndNoOtherName) {
  for (const char* name : {"a.png.tmp-12-3", "a.png.tmp-12-3@node-7.cluster", "manifest.json.tmp-1-0@n_1",
                           "slice_00001.png.tmp-999999-0@othernode"})
    EXPECT_TRUE(is_atomic_temporary_name(name)) << name;
  for (const char* name : {"a.png", "a.png.tmp-12-3@", "a.png.tmp-12-3@bad/host", "a.png.tmp-12-3@a b", ".tmp-1-2",
                           "a.png.tmp-x-3@h", "a.png.tmp-12-@h", "a.png.tmp--3"})
    EXPECT_FALSE(is_atomic_temporary_name(name)) << name;
  const std::string here = machine_name();
  EXPECT_FALSE(here.empty());
  EXPECT_LE(here.size(), 64u);
  EXPECT_EQ(here.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-_"),
            std::string::npos)
      << here;
}

// A shard that resumes cannot see another machine's processes: it keeps their temporaries
// (one may be a file another shard is writing right now) and removes this machine's whose
// process has ended; a whole job or a merge, which hold the folder alone, remove them all.
TEST(AtomicFile, AResumeRemovesAnotherMachinesTemporariesOnlyWhenItHoldsTheFolderAlone) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("trivox-atomic-stale-{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir / "vdb");
  const std::string here = machine_name();
  const fs::path mine_running = dir / fmt::format("a.png.tmp-{}-1@{}", ::getppid(), here);
  const fs::path mine_ended = dir / fmt::format("b.png.tmp-999999-1@{}", here);
  const fs::path old_ended = dir / "vdb" / "stack.vdb.tmp-999999-2";
  const fs::path other = dir / fmt::format("c.png.tmp-{}-1@{}-elsewhere", ::getppid(), here);
  const fs::path other_dead_pid = dir / "d.png.tmp-999999-1@othernode";
  for (const fs::path& p : {mine_running, mine_ended, old_ended, other, other_dead_pid}) std::ofstream(p) << "x";
  EXPECT_EQ(remove_stale_temporaries(dir, StaleTemporaries::kOfThisMachine), 2);
  EXPECT_TRUE(fs::exists(mine_running));
  EXPECT_FALSE(fs::exists(mine_ended));
  EXPECT_FALSE(fs::exists(old_ended));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_TRUE(fs::exists(other_dead_pid)) << "a pid of another machine was judged on this one";
  EXPECT_EQ(remove_stale_temporaries(dir, StaleTemporaries::kOfEveryMachine), 2);
  EXPECT_TRUE(fs::exists(mine_running)) << "a running process of this machine lost its file";
  EXPECT_FALSE(fs::exists(other));
  EXPECT_FALSE(fs::exists(other_dead_pid));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace trivox
