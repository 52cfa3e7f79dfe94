// The construction cache trusts nothing in its folder (docs/SLICING.md, "The construction
// cache"): an entry that is a directory, a FIFO, a device, a link to one or an implausibly
// large file is a warning and a rebuild, never a failure, a hang or an allocation of its size;
// an entry replaced with other geometry, its SHA-256 recomputed, is caught by the check of the
// volume against its inputs, for every constructor, and built again; a genuine entry passes
// that check.
#include <atomic>
#include <bit>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "construct/construct_fixtures.h"
#include "harness/fuzz_harness.h"
#include "harness/pipeline_job.h"
#include "scene/scene_test_util.h"
#include "trivox/error.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
namespace fs = std::filesystem;
using test::scene_with;

Scene read(const fs::path& dir, const ordered_json& geometry, ConstructionCache* cache) {
  return parse_scene(scene_with(geometry).dump(), dir / "scene.json", SceneReadOptions{nullptr, cache});
}

// A 5 mm plate and constructions of every kind from it.
const TensorSpline kPlate = test::bilinear_plate([](double a, double b) { return Vec3{10 + 10 * a, 0, 5 * b}; });
const TensorSpline kFlat = test::bilinear_plate([](double a, double b) { return Vec3{10 * a, 10 * b, 0}; });
const TensorSpline kDisc = test::rational_disc({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 2);

std::vector<ordered_json> constructions() {
  using test::inline_spline;
  const TensorSpline moved = kPlate.transformed([](std::span<double> p) { p[1] += 3; });
  return {
      {{"extrude", {{"surface", inline_spline(kFlat)}, {"vector_mm", {0, 0, 5}}}}},
      {{"ruled", {{"from", inline_spline(kPlate)}, {"to", inline_spline(moved)}}}},
      {{"revolve", {{"profile", inline_spline(kPlate)}, {"axis_point_mm", {1, 0, 0}}, {"angle_deg", 270}}}},
      {{"revolve", {{"profile", inline_spline(kPlate)}, {"angle_deg", 90}, {"angle_param", "u"}}}},
      {{"sweep",
        {{"section", inline_spline(kDisc)},
         {"path", inline_spline(test::circle_curve({0, 0, 0}, 15))},
         {"twist_deg", 30},
         {"stations", 12}}}},
      {{"shell", {{"surface", inline_spline(kPlate)}, {"thickness_mm", 0.5}, {"side", "centred"}}}},
      {{"shell", {{"surface", inline_spline(kFlat)}, {"thickness_mm", 5}}}},
      {{"coons", test::coons_box_faces()}},
  };
}

fs::path only_entry(const fs::path& dir) {
  fs::path entry;
  for (const auto& e : fs::directory_iterator(dir)) entry = e.path();
  return entry;
}

void expect_same_points(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.spline().points().size(), b.spline().points().size());
  for (std::size_t i = 0; i < a.spline().points().size(); ++i)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.spline().points()[i]),
              std::bit_cast<std::uint64_t>(b.spline().points()[i]));
}

TEST(ConstructionCacheTrust, AGenuineEntryOfEveryConstructorIsTakenAndAReplacedOneIsBuiltAgain) {
  for (const ordered_json& geometry : constructions()) {
    SCOPED_TRACE(geometry.begin().key());
    const fs::path dir = test::scratch_dir();
    const Scene plain = read(dir, geometry, nullptr);
    ConstructionCache first(dir / "cache");
    read(dir, geometry, &first);
    ASSERT_EQ(first.stored(), 1);
    ConstructionCache second(dir / "cache");
    const Scene cached = read(dir, geometry, &second);
    EXPECT_EQ(second.hits(), 1);
    EXPECT_TRUE(second.warnings().empty()) << second.warnings().front();
    expect_same_points(cached.cells[0].volume, plain.cells[0].volume);

    // Its volume stretched 3 times along z (the 5 mm plate sliced 15 mm tall) and sealed again.
    fuzz::damage_cache_entry(only_entry(dir / "cache"), fuzz::kReplacedGeometry);
    ConstructionCache third(dir / "cache");
    const Scene rebuilt = read(dir, geometry, &third);
    EXPECT_EQ(third.hits(), 0);
    EXPECT_EQ(third.stored(), 1);
    ASSERT_EQ(third.warnings().size(), 1u);
    EXPECT_NE(third.warnings()[0].find("does not agree with the inputs"), std::string::npos) << third.warnings()[0];
    expect_same_points(rebuilt.cells[0].volume, plain.cells[0].volume);
    ConstructionCache fourth(dir / "cache");
    read(dir, geometry, &fourth);
    EXPECT_EQ(fourth.hits(), 1);  // the entry was replaced by the rebuilt volume
  }
}

// Each entry that is not a regular file of a plausible size: a warning naming the entry and
// what it is, the volume built as without a cache.
TEST(ConstructionCacheTrust, AnEntryThatIsNoRegularFileIsAWarningAndARebuild) {
  const ordered_json geometry = constructions().front();
  struct Case {
    const char* name;
    int damage;  // fuzz::CacheDamage, or kNoCache for a sparse file of 100 GB
    const char* says;
  };
  const Case cases[] = {
      {"directory", fuzz::kDirectory, "is a directory"},
      {"fifo", fuzz::kFifo, "is a FIFO"},
      {"device link", fuzz::kDeviceLink, "is a character device"},
      {"sparse", fuzz::kNoCache, "bytes, more than"},
      {"truncated", fuzz::kTruncated, "is damaged"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = test::scratch_dir();
    const Scene plain = read(dir, geometry, nullptr);
    ConstructionCache first(dir / "cache");
    read(dir, geometry, &first);
    const fs::path entry = only_entry(dir / "cache");
    if (c.damage == fuzz::kNoCache)
      fs::resize_file(entry, std::uintmax_t{100} << 30);
    else
      fuzz::damage_cache_entry(entry, c.damage);
    ConstructionCache cache(dir / "cache");
    const Scene s = read(dir, geometry, &cache);
    EXPECT_EQ(cache.hits(), 0);
    ASSERT_GE(cache.warnings().size(), 1u);
    EXPECT_NE(cache.warnings()[0].find(entry.string()), std::string::npos) << cache.warnings()[0];
    EXPECT_NE(cache.warnings()[0].find(c.says), std::string::npos) << cache.warnings()[0];
    expect_same_points(s.cells[0].volume, plain.cells[0].volume);
    fs::remove_all(entry);
  }
}

// A stop (SIGTERM, Ctrl-C) while an entry is read ends the reading as a stop: not a warning, not
// a rebuild, and the entry stays for the next run, which takes it.
TEST(ConstructionCacheTrust, AStopWhileAnEntryIsReadIsAStopAndLeavesTheEntry) {
  const ordered_json geometry = constructions().front();
  const fs::path dir = test::scratch_dir();
  ConstructionCache first(dir / "cache");
  read(dir, geometry, &first);
  const fs::path entry = only_entry(dir / "cache");
  const std::string key = entry.stem().string();
  ConstructionCache cache(dir / "cache");
  std::atomic<bool> stop{true};
  EXPECT_THROW((void)cache.load(key, &stop), CancelledError);
  EXPECT_TRUE(cache.warnings().empty());
  EXPECT_TRUE(fs::is_regular_file(entry));
  stop = false;
  EXPECT_TRUE(cache.load(key, &stop).has_value());
  EXPECT_EQ(cache.hits(), 1);
}

}  // namespace
}  // namespace trivox
