// Input files by kind and by content before they are trusted: a path that names a device, a
// FIFO or a directory is refused as what it is (never read, never blocking, never "missing");
// an ASCII STL vertex of two numbers names its line; a model number that would overflow is
// refused where it is read, naming the line; a stop flag ends every reader of input files
// as a stop, not as a fault of the file.
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <span>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include "mesh/mesh_fixtures.h"
#include "scene/scene_test_util.h"
#include "trivox/cancel.h"
#include "trivox/error.h"
#include "trivox/io/detail/regular_file.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/io/model.h"
#include "trivox/io/triangle_mesh.h"
#include "trivox/limits.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

template <class F>
std::string io_error_of(F f) {
  return test::error_of<IoError>(f);
}

// The InputError of reading `text` as an STL file: its line and message.
std::pair<int, std::string> stl_error(const std::string& text) {
  try {
    read_triangle_mesh(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), ".stl", "a.stl");
  } catch (const InputError& e) {
    return {e.line(), e.what()};
  }
  ADD_FAILURE() << "accepted";
  return {-1, ""};
}

TEST(InputFile, EachKindOfPathIsNamedAsWhatItIs) {
  const fs::path dir = test::scratch_dir();
  test::write_file(dir / "file", "abc");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", dir / "zero");
  EXPECT_EQ(not_a_regular_file(dir / "file"), std::nullopt);
  EXPECT_EQ(not_a_regular_file(dir / "absent"), "no file");
  EXPECT_EQ(not_a_regular_file(dir), "a directory");
  EXPECT_EQ(not_a_regular_file(dir / "fifo"), "a FIFO");
  EXPECT_EQ(not_a_regular_file("/dev/zero"), "a character device");
  EXPECT_EQ(not_a_regular_file(dir / "zero"), "a character device");
  EXPECT_EQ(read_regular_file(dir / "file", 3), "abc");
  EXPECT_NE(io_error_of([&] { read_regular_file(dir / "file", 2); }).find("has 3 bytes, more than the 2"),
            std::string::npos);
  // Opened without blocking: a FIFO with no writer returns at once, refused by its kind.
  EXPECT_NE(io_error_of([&] { read_regular_file(dir / "fifo", 1000); }).find("is a FIFO, not a regular file"),
            std::string::npos);
  EXPECT_NE(io_error_of([&] { read_regular_file(dir / "zero", 1000); }).find("is a character device"),
            std::string::npos);
}

TEST(InputFile, ModelAndMeshReadersRefuseADeviceByWhatItIs) {
  const fs::path dir = test::scratch_dir();
  fs::create_symlink("/dev/zero", dir / "part.g2");
  fs::create_symlink("/dev/zero", dir / "part.stl");
  EXPECT_NE(io_error_of([&] { read_model(dir / "part.g2"); }).find("is a character device, not a regular file"),
            std::string::npos);
  EXPECT_NE(
      io_error_of([&] { read_triangle_mesh(dir / "part.stl"); }).find("is a character device, not a regular file"),
      std::string::npos);
}

TEST(InputFile, ASceneNamesAModelFileThatIsADeviceAsSuch) {
  const fs::path dir = test::scratch_dir();
  fs::create_symlink("/dev/zero", dir / "part.itd");
  test::expect_scene_error(
      R"({"units": "mm", "printer": "j750-hq", "materials": [{"name": "A", "rgba": [0, 0, 0, 255]}],
          "cells": [{"name": "c", "geometry": {"file": "part.itd"}, "material": "A"}]})",
      "/cells/0/geometry/file", "is a character device, not a regular file", dir);
}

// In a child process: exits 0 when, under an address-space limit of 3 GB, the triangle limit
// is below 20 million.
[[noreturn]] void exit_with_the_limit_under_3_gb() {
  rlimit rl{};
  rl.rlim_cur = rl.rlim_max = std::uint64_t{3} << 30;
  ::setrlimit(RLIMIT_AS, &rl);
  std::exit(mesh_triangle_limit() < 20'000'000 ? 0 : 1);
}

// The triangle limit follows the memory budget: half of what the process may use, at
// kMeshTrimBytesPerTriangle a triangle; under an address-space limit of 3 GB (in a child
// process) 20 million triangles are beyond it.
TEST(InputFile, TheTriangleLimitComesFromTheMemoryBudget) {
  const auto memory = process_memory_limit_bytes();
  ASSERT_TRUE(memory);
  EXPECT_EQ(
      mesh_triangle_limit(),
      std::min<std::int64_t>(kMaxMeshTriangles, static_cast<std::int64_t>(*memory / 2 / kMeshTrimBytesPerTriangle)));
#if defined(__SANITIZE_ADDRESS__)
  // An address-space limit of 3 GB leaves AddressSanitizer no room for its shadow memory.
  GTEST_SKIP() << "RLIMIT_AS under 3 GB cannot be set under AddressSanitizer";
#endif
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(exit_with_the_limit_under_3_gb(), ::testing::ExitedWithCode(0), "");
}

// An ASCII STL whose vertex has two numbers: the line is named and the message quotes what the
// file holds.
TEST(InputFile, AnAsciiStlVertexOfTwoNumbersNamesItsLine) {
  std::string stl = test::ascii_stl(test::box_mesh({0, 0, 0}, {1, 1, 1}));
  const std::size_t at = stl.find("vertex", stl.find("vertex") + 1);
  const std::size_t end = stl.find('\n', at);
  const int line = 1 + static_cast<int>(std::count(stl.begin(), stl.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  stl.replace(at, end - at, "vertex 1 2");
  auto [at_line, what] = stl_error(stl);
  EXPECT_EQ(at_line, line) << what;
  EXPECT_NE(what.find("a vertex has 2 numbers; it needs three"), std::string::npos) << what;
  stl.replace(at, 10, "vertex 1 2 x");
  std::tie(at_line, what) = stl_error(stl);
  EXPECT_EQ(at_line, line) << what;
  EXPECT_NE(what.find("\"x\" where a finite number belongs"), std::string::npos) << what;
}

// A corner at 1e308: refused by the reader as overflowing, on its line, not later as a
// degenerate volume (det J infinite or undefined).
TEST(InputFile, AG2NumberThatWouldOverflowIsRefusedOnItsLine) {
  const std::string text =
      "700 1 0 0\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1e308 1 1\n";
  try {
    read_g2(text, "far.g2");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 16) << e.what();
    EXPECT_NE(std::string(e.what()).find("overflows"), std::string::npos) << e.what();
  }
}

// A rational spline whose numbers are within the model limit but whose weighted coordinates
// (what .itd and .g2 hold) or coordinates (what G+Smo holds) would not be, once read: 1e100 / 9
// multiplied back by 9 rounds to 1.0000000000000002e100. Refused by the reader, naming the
// patch's line, so that every model trivox takes writes back to a file that reads again.
TEST(InputFile, ARationalSplineWhoseWrittenNumbersWouldOverflowIsRefusedOnItsLine) {
  for (const char* first : {"[9 1e100]", "[0.5 1e100]"}) {
    const std::string text = std::string("[OBJECT C\n    [CURVE BSPLINE 2 2 P1\n        [KV 0 0 1 1]\n        ") +
                             first + "\n        [7 1e100]\n    ]\n]\n";
    try {
      (void)read_itd(text, "round.itd");
      ADD_FAILURE() << first << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), 2) << e.what();
      EXPECT_NE(std::string(e.what()).find("which overflows"), std::string::npos) << e.what();
    }
  }
  // Within the limit after the round trip: taken, and written back it reads again.
  const Model m = read_itd(
      "[OBJECT C\n    [CURVE BSPLINE 2 2 P1\n        [KV 0 0 1 1]\n        [9 1e99]\n"
      "        [7 1e99]\n    ]\n]\n",
      "round.itd");
  std::ostringstream out;
  write_itd(out, m);
  EXPECT_NO_THROW((void)read_itd(out.str(), "again.itd"));
}

// The reads of a few numbers each a model's parser makes (tokens, values) read the flag at
// the first and then every 65536th: a raised flag is seen within that many, not at the end.
TEST(InputFile, AStopPollReadsTheFlagAtTheFirstStepAndEvery65536th) {
  std::atomic<bool> stop{false};
  StopPoll poll(&stop, "counting");
  poll.step();  // the first: read, lowered
  stop = true;
  for (int i = 1; i < 65536; ++i) ASSERT_NO_THROW(poll.step()) << i;
  try {
    poll.step();
    ADD_FAILURE() << "the 65537th step did not read the flag";
  } catch (const CancelledError& e) {
    EXPECT_STREQ(e.what(), "stopped while counting");
  }
  StopPoll none(nullptr, "nothing");
  for (int i = 0; i < 70000; ++i) ASSERT_NO_THROW(none.step());
}

// A volume of 30 x 30 x 30 control points: 108,000 numbers in a file, past one poll's span.
Model big_model() {
  std::vector<double> knots{0, 0};
  for (int i = 1; i <= 28; ++i) knots.push_back(i / 29.0);
  knots.push_back(1);
  knots.push_back(1);
  const KnotVector kv(2, knots);
  std::vector<double> points;
  for (int k = 0; k < 30; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 30; ++i) points.insert(points.end(), {i * 1.0, j * 1.0, k * 1.0});
  return Model{"big", {Patch{"V", 0, 0, TensorSpline({kv, kv, kv}, 3, points)}}, {}};
}

// Reading a model or a mesh file (SIGTERM from a scheduler, Ctrl-C) stops at the flag: each
// reader from text, each file reader, the hash a scene takes of its files. With the flag
// lowered, the same calls read the same inputs.
TEST(InputFile, AStopFlagEndsEveryReaderOfModelsAndMeshesAsAStop) {
  const Model model = big_model();
  std::atomic<bool> stop{true};
  const fs::path dir = test::scratch_dir();
  using Reader = Model (*)(std::string_view, const std::string&, const std::atomic<bool>*);
  const std::tuple<ModelFormat, Reader, const char*> formats[] = {{ModelFormat::kItd, &read_itd, "big.itd"},
                                                                  {ModelFormat::kG2, &read_g2, "big.g2"},
                                                                  {ModelFormat::kGismoXml, &read_gismo_xml, "big.xml"}};
  for (const auto& [format, reader, name] : formats) {
    SCOPED_TRACE(name);
    std::ostringstream out;
    write_model(out, model, format);
    test::write_file(dir / name, out.str());
    stop = true;
    EXPECT_THROW((void)reader(out.str(), name, &stop), CancelledError);
    EXPECT_THROW((void)read_model(dir / name, &stop), CancelledError);
    EXPECT_THROW((void)sha256_file(dir / name, &stop), CancelledError);
    stop = false;
    const Model back = reader(out.str(), name, &stop);
    ASSERT_EQ(back.patches.size(), 1u);
    const auto got = back.patches[0].spline.points(), want = model.patches[0].spline.points();
    EXPECT_TRUE(std::equal(got.begin(), got.end(), want.begin(), want.end()));
    EXPECT_EQ(read_model(dir / name, &stop).patches.size(), 1u);
  }
  const test::TestMesh sphere = test::sphere_mesh({0, 0, 0}, 1, 40, 80);
  const std::pair<std::string, const char*> meshes[] = {
      {test::binary_stl(sphere), "s.stl"}, {test::ascii_stl(sphere), "a.stl"}, {test::obj_text(sphere), "s.obj"}};
  for (const auto& [bytes, name] : meshes) {
    SCOPED_TRACE(name);
    test::write_file(dir / name, bytes);
    const std::span<const std::uint8_t> data(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    const std::string ext = fs::path(name).extension().string();
    stop = true;
    EXPECT_THROW((void)read_triangle_mesh(data, ext, name, &stop), CancelledError);
    EXPECT_THROW((void)read_triangle_mesh(dir / name, &stop), CancelledError);
    stop = false;
    EXPECT_EQ(read_triangle_mesh(data, ext, name, &stop).triangles.size(), sphere.triangles.size());
  }
}

}  // namespace
}  // namespace trivox
