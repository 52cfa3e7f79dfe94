// The construction cache: an entry gives back the volume and report it was made from, bit for
// bit; every damaged entry is refused (never misread, never a crash); a scene read through the
// cache gets the volume a read without it builds, and builds again when the constructor, a
// model file it names or the entry changed.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "construct/construct_fixtures.h"
#include "scene/scene_test_util.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/extrude.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/untangle.h"
#include "trivox/io/detail/sha256.h"
#include "trivox/io/model.h"
#include "trivox/scene/construction_cache.h"
#include "trivox/scene/scene.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
namespace fs = std::filesystem;

const std::string kKey = sha256_hex("a construction");
const std::string kOtherKey = sha256_hex("another construction");

// A biquadratic face of the box [0, 10]^3: corner `o`, edges `a` and `b`, its middle control
// point moved by `dent`.
TensorSpline face(Vec3 o, Vec3 a, Vec3 b, Vec3 dent = {}) {
  std::vector<double> pts;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      Vec3 p = o + (0.5 * i) * a + (0.5 * j) * b;
      if (i == 1 && j == 1) p = p + dent;
      pts.insert(pts.end(), {p.x, p.y, p.z});
    }
  const KnotVector k = KnotVector::bezier(3);
  return TensorSpline({k, k}, 3, std::move(pts));
}

// The six faces of a box whose top is dented down, its middle control point `depth` below the
// bottom (the surface itself stays above it).
Model dented_box(double depth) {
  const Vec3 x{10, 0, 0}, y{0, 10, 0}, z{0, 0, 10};
  Model m;
  const std::vector<TensorSpline> faces = {face({0, 0, 0}, x, y), face({0, 0, 10}, x, y, {0, 0, -10 - depth}),
                                           face({0, 0, 0}, y, z), face({10, 0, 0}, y, z),
                                           face({0, 0, 0}, x, z), face({0, 10, 0}, x, z)};
  for (std::size_t i = 0; i < faces.size(); ++i) m.patches.push_back({"FACE", static_cast<int>(i), 0, faces[i]});
  return m;
}

void write_model_file(const fs::path& path, const Model& m) {
  std::ofstream out(path);
  write_itd(out, m);
}

ordered_json coons_scene(int iterations = 40) {
  ordered_json geometry = {
      {"coons",
       {{"faces", {{"file", "box.itd"}}}, {"untangle", {{"iterations", iterations}}}, {"jacobian_samples", 9}}}};
  return {{"units", "mm"},
          {"printer", "j750-hq"},
          {"materials", {{{"name", "A"}, {"rgba", {0, 0, 0, 255}}}}},
          {"cells",
           {{{"name", "c"},
             {"geometry", geometry},
             {"placement", {{"scale", 2}}},
             {"material", {{"kind", "constant"}, {"fractions", {{"A", 1}}}}}}}}};
}

std::uint64_t bits(double d) { return std::bit_cast<std::uint64_t>(d); }

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_same_bits(const TensorSpline& a, const TensorSpline& b) {
  ASSERT_EQ(a.all_knots().size(), b.all_knots().size());
  for (std::size_t d = 0; d < a.all_knots().size(); ++d) {
    EXPECT_EQ(a.all_knots()[d].order(), b.all_knots()[d].order());
    EXPECT_EQ(a.all_knots()[d].is_periodic(), b.all_knots()[d].is_periodic());
    const auto ka = a.all_knots()[d].knots(), kb = b.all_knots()[d].knots();
    ASSERT_EQ(ka.size(), kb.size());
    for (std::size_t i = 0; i < ka.size(); ++i) EXPECT_EQ(bits(ka[i]), bits(kb[i]));
  }
  ASSERT_EQ(a.points().size(), b.points().size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.points().size(); ++i) differ += bits(a.points()[i]) != bits(b.points()[i]);
  EXPECT_EQ(differ, 0u);
  ASSERT_EQ(a.weights().size(), b.weights().size());
  for (std::size_t i = 0; i < a.weights().size(); ++i) EXPECT_EQ(bits(a.weights()[i]), bits(b.weights()[i]));
}

void expect_same_report(const ConstructionReport& a, const ConstructionReport& b) {
  EXPECT_EQ(a.constructor, b.constructor);
  EXPECT_EQ(a.jacobian.classification, b.jacobian.classification);
  EXPECT_EQ(a.jacobian.positive, b.jacobian.positive);
  EXPECT_EQ(a.jacobian.negative, b.jacobian.negative);
  EXPECT_EQ(a.jacobian.zero, b.jacobian.zero);
  EXPECT_EQ(bits(a.jacobian.min_det), bits(b.jacobian.min_det));
  EXPECT_EQ(bits(a.jacobian.max_det), bits(b.jacobian.max_det));
  for (const auto& [ra, rb] : {std::pair{a.minority_sign, b.minority_sign}, std::pair{a.zero, b.zero}}) {
    EXPECT_EQ(ra.samples, rb.samples);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(bits(ra.box.lo[c]), bits(rb.box.lo[c]));
      EXPECT_EQ(bits(ra.box.hi[c]), bits(rb.box.hi[c]));
    }
  }
  EXPECT_EQ(a.exact, b.exact);
  EXPECT_EQ(bits(a.approximation_error_mm), bits(b.approximation_error_mm));
}

// Two constructions: a rational revolve (weights, an exact report) and a ruled volume that
// folds (minority-sign and zero regions set).
std::vector<Constructed> samples() {
  std::vector<Constructed> out;
  out.push_back(revolve(test::rational_disc({20, 0, 0}, {1, 0, 0}, {0, 0, 1}, 5), {{0, 0, 0}, {0, 0, 1}, 270}));
  // The top plate is the bottom one mirrored in x: the rulings cross at mid-height.
  const TensorSpline bottom = test::bilinear_plate([](double a, double b) { return Vec3{10 * a, 10 * b, 0}; });
  const TensorSpline top = test::bilinear_plate([](double a, double b) { return Vec3{10 - 10 * a, 10 * b, 4}; });
  out.push_back(ruled(bottom, top, RuledParams{{17}}));
  EXPECT_TRUE(out.back().report.folds());
  EXPECT_GT(out.back().report.minority_sign.samples, 0);
  EXPECT_GT(out.back().report.zero.samples, 0);
  out.back().report.exact = false;  // every field away from its default
  out.back().report.approximation_error_mm = 0.1;
  return out;
}

TEST(ConstructionCache, AnEntryGivesBackItsVolumeAndReportBitForBit) {
  for (const Constructed& c : samples()) {
    const std::string bytes = encode_construction_entry(kKey, c);
    std::string problem;
    const auto back = decode_construction_entry(bytes, kKey, &problem);
    ASSERT_TRUE(back) << problem;
    expect_same_bits(back->volume.spline(), c.volume.spline());
    expect_same_report(back->report, c.report);
    EXPECT_EQ(encode_construction_entry(kKey, *back), bytes);
  }
}

TEST(ConstructionCache, EveryDamagedEntryIsRefused) {
  const Constructed c = samples().front();
  const std::string good = encode_construction_entry(kKey, c);
  std::string problem;
  ASSERT_TRUE(decode_construction_entry(good, kKey, &problem));
  EXPECT_FALSE(decode_construction_entry(good, kOtherKey, &problem));
  EXPECT_NE(problem.find("another key"), std::string::npos) << problem;
  // Every byte changed, every length cut short, a byte added.
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x10);
    problem.clear();
    EXPECT_FALSE(decode_construction_entry(bad, kKey, &problem)) << "byte " << i;
    EXPECT_FALSE(problem.empty());
  }
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_FALSE(decode_construction_entry(std::string_view(good).substr(0, n), kKey, &problem)) << n << " bytes";
  EXPECT_FALSE(decode_construction_entry(good + '\0', kKey, &problem));
}

// An entry written by hand, its header consistent (docs/FORMATS.md): what the payload says
// is checked too, and a count larger than the entry is refused before anything is allocated.
std::string entry_with_payload(const std::string& payload) {
  std::string e = "TRIVOXCV";
  e += std::string("\x01\x00\x00\x00", 4);
  e += kKey;
  for (int i = 0; i < 8; ++i) e += static_cast<char>((payload.size() >> (8 * i)) & 0xff);
  e += sha256_hex(payload);
  return e + payload;
}

std::string le(std::uint64_t v, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += static_cast<char>((v >> (8 * i)) & 0xff);
  return s;
}

TEST(ConstructionCache, AWellSealedEntryWithBadContentIsRefused) {
  const std::string good = encode_construction_entry(kKey, samples().front());
  const std::string payload = good.substr(8 + 4 + 64 + 8 + 64);
  std::string problem;
  ASSERT_TRUE(decode_construction_entry(entry_with_payload(payload), kKey, &problem)) << problem;
  // The first knot vector's knot count: 2^62 numbers.
  std::string huge = payload;
  huge.replace(4 + 4 + 4 + 1 + 4, 8, le(std::uint64_t{1} << 62, 8));
  EXPECT_FALSE(decode_construction_entry(entry_with_payload(huge), kKey, &problem));
  EXPECT_NE(problem.find("too large"), std::string::npos) << problem;
  // A knot vector of order 0, and of order 33.
  for (std::uint64_t order : {0, 33}) {
    std::string bad = payload;
    bad.replace(8, 4, le(order, 4));
    EXPECT_FALSE(decode_construction_entry(entry_with_payload(bad), kKey, &problem)) << order;
  }
  // A surface instead of a trivariate.
  std::string surface = payload;
  surface.replace(0, 4, le(2, 4));
  EXPECT_FALSE(decode_construction_entry(entry_with_payload(surface), kKey, &problem));
  // A first knot that is NaN: the volume is not valid.
  std::string nan = payload;
  nan.replace(4 + 4 + 4 + 1 + 4 + 8, 8, le(0x7ff8000000000000ULL, 8));
  EXPECT_FALSE(decode_construction_entry(entry_with_payload(nan), kKey, &problem));
  EXPECT_NE(problem.find("not valid"), std::string::npos) << problem;
  // A Jacobian classification beyond the last.
  std::string cls = payload;
  const std::size_t report = payload.size() - (4 + 7 + 4 + 3 * 4 + 2 * 8 + 2 * (4 + 6 * 8) + 1 + 8);
  ASSERT_EQ(payload.substr(report, 4), le(7, 4));  // "revolve"
  cls.replace(report + 4 + 7, 4, le(9, 4));
  EXPECT_FALSE(decode_construction_entry(entry_with_payload(cls), kKey, &problem));
  // Bytes after the report.
  EXPECT_FALSE(decode_construction_entry(entry_with_payload(payload + "x"), kKey, &problem));
}

// The scene `dir/scene.json` read with the cache in `dir/cache` (or without one).
Scene read(const fs::path& dir, const ordered_json& scene, ConstructionCache* cache, int indent = -1) {
  return parse_scene(scene.dump(indent), dir / "scene.json", SceneReadOptions{nullptr, cache});
}

TEST(ConstructionCache, ASceneTakesTheVolumeItsFirstReadStored) {
  const fs::path dir = test::scratch_dir();
  write_model_file(dir / "box.itd", dented_box(4));
  const Scene plain = read(dir, coons_scene(), nullptr);
  ConstructionCache first(dir / "cache");
  const Scene built = read(dir, coons_scene(), &first);
  EXPECT_EQ(first.stored(), 1);
  EXPECT_EQ(first.hits(), 0);
  EXPECT_TRUE(first.warnings().empty());
  ConstructionCache second(dir / "cache");
  const Scene cached = read(dir, coons_scene(), &second);
  EXPECT_EQ(second.hits(), 1);
  EXPECT_EQ(second.stored(), 0);
  for (const Scene* s : {&built, &cached}) {
    expect_same_bits(s->cells[0].volume.spline(), plain.cells[0].volume.spline());
    // What a job's manifest records of the scene is the same too.
    ASSERT_EQ(s->input_files.size(), plain.input_files.size());
    EXPECT_EQ(s->input_files[0].name, plain.input_files[0].name);
    EXPECT_EQ(s->input_files[0].sha256, plain.input_files[0].sha256);
    EXPECT_EQ(s->cells[0].fingerprint, plain.cells[0].fingerprint);
  }
  // The volume is the untangled one: a knot was inserted in each direction (27 control points
  // before).
  EXPECT_EQ(plain.cells[0].volume.spline().total_ctrl(), 64);
  // Whitespace and the order of keys are not part of the key.
  ordered_json reordered = coons_scene();
  ordered_json& c = reordered["cells"][0]["geometry"]["coons"];
  c = ordered_json{{"jacobian_samples", 9}, {"untangle", c["untangle"]}, {"faces", c["faces"]}};
  ConstructionCache third(dir / "cache");
  read(dir, reordered, &third, 2);
  EXPECT_EQ(third.hits(), 1);
}

TEST(ConstructionCache, AChangedModelFileOrParameterIsBuiltAgain) {
  const fs::path dir = test::scratch_dir();
  write_model_file(dir / "box.itd", dented_box(4));
  {
    ConstructionCache cache(dir / "cache");
    read(dir, coons_scene(), &cache);
    ASSERT_EQ(cache.stored(), 1);
  }
  write_model_file(dir / "box.itd", dented_box(3));
  const Scene plain = read(dir, coons_scene(), nullptr);
  ConstructionCache cache(dir / "cache");
  const Scene s = read(dir, coons_scene(), &cache);
  EXPECT_EQ(cache.hits(), 0);
  EXPECT_EQ(cache.stored(), 1);
  expect_same_bits(s.cells[0].volume.spline(), plain.cells[0].volume.spline());
  ConstructionCache other(dir / "cache");
  read(dir, coons_scene(12), &other);
  EXPECT_EQ(other.hits(), 0);
  EXPECT_EQ(other.stored(), 1);
  // The placement is applied after the construction: a new scale takes the cached volume.
  ordered_json scaled = coons_scene();
  scaled["cells"][0]["placement"]["scale"] = 3;
  ConstructionCache again(dir / "cache");
  const Scene big = read(dir, scaled, &again);
  EXPECT_EQ(again.hits(), 1);
  const auto far =
      std::max_element(plain.cells[0].volume.spline().points().begin(), plain.cells[0].volume.spline().points().end()) -
      plain.cells[0].volume.spline().points().begin();
  const double p2 = plain.cells[0].volume.spline().points()[static_cast<std::size_t>(far)],
               p3 = big.cells[0].volume.spline().points()[static_cast<std::size_t>(far)];
  EXPECT_NEAR(p3, 1.5 * p2, 1e-12 * std::abs(p3));
  EXPECT_NE(p2, p3);
}

TEST(ConstructionCache, ADamagedEntryIsBuiltAgainWithAWarningAndReplaced) {
  const fs::path dir = test::scratch_dir();
  write_model_file(dir / "box.itd", dented_box(4));
  const Scene plain = read(dir, coons_scene(), nullptr);
  ConstructionCache first(dir / "cache");
  read(dir, coons_scene(), &first);
  ASSERT_EQ(first.stored(), 1);
  fs::path entry;
  for (const auto& e : fs::directory_iterator(dir / "cache")) entry = e.path();
  std::string bytes = read_text(entry);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 1);
  test::write_file(entry, bytes);
  ConstructionCache second(dir / "cache");
  const Scene s = read(dir, coons_scene(), &second);
  ASSERT_EQ(second.warnings().size(), 1u);
  EXPECT_NE(second.warnings()[0].find("is damaged (its SHA-256 differs"), std::string::npos) << second.warnings()[0];
  EXPECT_EQ(second.hits(), 0);
  EXPECT_EQ(second.stored(), 1);
  expect_same_bits(s.cells[0].volume.spline(), plain.cells[0].volume.spline());
  ConstructionCache third(dir / "cache");
  read(dir, coons_scene(), &third);
  EXPECT_EQ(third.hits(), 1);
  EXPECT_TRUE(third.warnings().empty());
  // An entry moved to another key's name is refused as well.
  ConstructionCache fourth(dir / "cache");
  read(dir, coons_scene(12), &fourth);
  ASSERT_EQ(fourth.stored(), 1);
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(dir / "cache")) entries.push_back(e.path());
  ASSERT_EQ(entries.size(), 2u);
  fs::rename(entries[0], dir / "swap");
  fs::rename(entries[1], entries[0]);
  fs::rename(dir / "swap", entries[1]);
  ConstructionCache fifth(dir / "cache");
  read(dir, coons_scene(), &fifth);
  EXPECT_EQ(fifth.hits(), 0);
  ASSERT_EQ(fifth.warnings().size(), 1u);
  EXPECT_NE(fifth.warnings()[0].find("another key"), std::string::npos) << fifth.warnings()[0];
}

TEST(ConstructionCache, ACacheThatCannotBeWrittenIsAWarningOnly) {
  const fs::path dir = test::scratch_dir();
  write_model_file(dir / "box.itd", dented_box(4));
  test::write_file(dir / "a file", "not a folder");
  ConstructionCache cache(dir / "a file" / "cache");
  const Scene s = read(dir, coons_scene(), &cache);
  EXPECT_EQ(s.cells.size(), 1u);
  EXPECT_EQ(cache.stored(), 0);
  ASSERT_EQ(cache.warnings().size(), 1u);
  EXPECT_NE(cache.warnings()[0].find("cannot store"), std::string::npos) << cache.warnings()[0];
}

TEST(ConstructionCache, TheProgramIsPartOfTheKey) {
  const auto digest = this_program_sha256();
  ASSERT_TRUE(digest);
  EXPECT_EQ(digest->size(), 64u);
  ConstructionCache cache(test::scratch_dir() / "cache");
  EXPECT_NE(cache.program_identity().find(*digest), std::string::npos) << cache.program_identity();
}

}  // namespace
}  // namespace trivox
