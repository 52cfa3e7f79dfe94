// GoTools .g2 reader and writer on small hand-written files whose values are known: the
// header and its auxiliary values, orders (not degrees), homogeneous rational coefficients,
// several objects, skipped classes with their note; every rule of the reader with its line;
// counts refused before anything is allocated; write_g2 round trips and read_model's dispatch.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

std::vector<double> eval(const TensorSpline& s, std::vector<double> t) {
  std::vector<double> out(static_cast<std::size_t>(s.point_dim()));
  s.evaluate(t, out);
  return out;
}

// A trilinear volume on [0,1] x [0,1] x [0,2] mapping onto [2,4] x [-1,1] x [0.5,3].
constexpr const char* kVolume =
    "700 1 0 0\n"
    "3 0\n"
    "2 2\n0 0 1 1\n"
    "2 2\n0 0 1 1\n"
    "2 2\n0 0 2 2\n"
    "2 -1 0.5\n4 -1 0.5\n2 1 0.5\n4 1 0.5\n"
    "2 -1 3\n4 -1 3\n2 1 3\n4 1 3\n";

TEST(G2Reader, ReadsAVolumeWithOrdersAndKnots) {
  const Model m = read_g2(kVolume, "vol.g2");
  ASSERT_EQ(m.patches.size(), 1u);
  const Patch& p = m.patches[0];
  EXPECT_EQ(p.name, "SplineVolume #0");
  EXPECT_EQ(p.source_line, 1);
  EXPECT_TRUE(p.header_aux.empty());
  const TensorSpline& s = p.spline;
  ASSERT_EQ(s.param_dim(), 3);
  EXPECT_EQ(s.point_dim(), 3);
  EXPECT_FALSE(s.is_rational());
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(s.knots(d).order(), 2);  // "2 2": two coefficients of ORDER 2 (linear)
    EXPECT_EQ(s.num_ctrl(d), 2);
  }
  EXPECT_EQ(s.hi(2), 2.0);
  EXPECT_EQ(eval(s, {0.5, 0.5, 1.0}), (std::vector<double>{3.0, 0.0, 1.75}));
  EXPECT_EQ(eval(s, {1.0, 0.0, 2.0}), (std::vector<double>{4.0, -1.0, 3.0}));
  EXPECT_TRUE(m.notes.empty());
}

TEST(G2Reader, RationalCoefficientsAreHomogeneousWithTheWeightLast) {
  // A quarter circle of radius 2 as a rational quadratic SplineCurve in the plane: points
  // (2,0), (2,2), (0,2) with weights 1, 1/sqrt(2), 1, stored as (w*x, w*y, w).
  const double h = std::sqrt(0.5);
  std::ostringstream text;
  text.precision(17);
  text << "100 1 0 0\n2 1\n3 3\n0 0 0 1 1 1\n2 0 1\n" << 2 * h << ' ' << 2 * h << ' ' << h << "\n0 2 1\n";
  const Model m = read_g2(text.str(), "arc.g2");
  ASSERT_EQ(m.patches.size(), 1u);
  const TensorSpline& s = m.patches[0].spline;
  ASSERT_EQ(s.param_dim(), 1);
  ASSERT_EQ(s.point_dim(), 2);
  ASSERT_TRUE(s.is_rational());
  EXPECT_NEAR(s.weight(1), h, 1e-16);
  EXPECT_NEAR(s.point(1)[0], 2.0, 1e-15);  // divided by the weight
  EXPECT_NEAR(s.point(1)[1], 2.0, 1e-15);
  for (double t : {0.1, 0.5, 0.77}) {
    const std::vector<double> p = eval(s, {t});
    EXPECT_NEAR(std::hypot(p[0], p[1]), 2.0, 1e-14) << t;  // on the circle: the weights were read
  }
  const std::vector<double> mid = eval(s, {0.5});
  EXPECT_NEAR(mid[0], 2 * h, 1e-14);
}

TEST(G2Reader, SeveralObjectsAuxiliaryValuesAndSkippedClasses) {
  const std::string text =
      "200 1 0 4 255 0 0 255\n"  // a red surface: four auxiliary integers
      "3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 1\n"
      "\n"
      "120 1 0 0\n"  // a Line: trivox skips it up to the next header
      "3\n0 0 0 1 0 0\n"
      "0 1 1\n"
      "700 1 0 0\n"
      "1 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0\n1\n2\n3\n4\n5\n6\n7\n";
  const Model m = read_g2(text, "mixed.g2");
  ASSERT_EQ(m.patches.size(), 2u);
  EXPECT_EQ(m.patches[0].name, "SplineSurface #0");
  EXPECT_EQ(m.patches[0].header_aux, (std::vector<int>{255, 0, 0, 255}));
  EXPECT_EQ(m.patches[0].spline.param_dim(), 2);
  EXPECT_EQ(eval(m.patches[0].spline, {0.5, 0.5}), (std::vector<double>{0.5, 0.5, 0.25}));
  EXPECT_EQ(m.patches[1].name, "SplineVolume #2");  // object 2 of the file: the Line was object 1
  EXPECT_EQ(m.patches[1].id, 1);
  EXPECT_EQ(m.patches[1].source_line, 16);
  EXPECT_EQ(m.patches[1].spline.point_dim(), 1);  // a scalar field is a patch like any other
  EXPECT_EQ(eval(m.patches[1].spline, {1.0, 1.0, 1.0}), (std::vector<double>{7.0}));
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_EQ(m.notes[0].line, 12);
  EXPECT_NE(m.notes[0].text.find("Line (class 120, lines 12 to 15)"), std::string::npos) << m.notes[0].text;
}

TEST(G2Reader, HeaderOnAnyLineLayoutAndTrailingSkippedObject) {
  // GoTools reads with operator>>: line breaks carry no meaning.
  const Model m = read_g2(
      "700 1 0\n0 3\n0 2 2 0 0 1 1 2 2 0 0 1 1 2 2 0 0 1 1 0 0 0 1 0 0 0 1 0 1 1 0 0 0 1 1 0 1 0 1 "
      "1 1 1 1\n410 1 0 0\nwhatever a line cloud holds\n",
      "layout.g2");
  ASSERT_EQ(m.patches.size(), 1u);
  EXPECT_EQ(eval(m.patches[0].spline, {0.25, 0.5, 1.0}), (std::vector<double>{0.25, 0.5, 1.0}));
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_NE(m.notes[0].text.find("LineCloud (class 410, lines 4 to 5)"), std::string::npos) << m.notes[0].text;
}

struct Bad {
  const char* what;
  std::string text;
  int line;
  const char* message;
};

TEST(G2Reader, EveryRuleNamesTheLine) {
  const std::string bases = "2 2\n0 0 1 1\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n";
  const std::string points = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n";
  const std::string six_weighted = "0 0 1 1\n1 1 0 1\n0 0 1 1\n1 0 1 1\n0 1 1 1\n1 1 1 1\n";
  const std::vector<Bad> cases = {
      {"empty", " \n\n", 0, "file is empty"},
      {"not a class", "hello 1 0 0\n", 1, "expected a class number"},
      {"unknown class", "701 1 0 0\n", 1, "701 is not a GoTools class number"},
      {"version", "700 2 0 0\n", 1, "version 2"},
      {"negative aux count", "700 1 0 -1\n", 1, "number of auxiliary header values is -1"},
      {"aux not an integer", "700 1 0 1 0.5\n", 1, "auxiliary header value 1 of 1"},
      {"dimension 0", "700 1 0 0\n0 0\n", 2, "dimension (coordinates per point) is 0"},
      {"rational flag 2", "700 1 0 0\n3 2\n", 2, "rational flag (0 or 1) is 2"},
      {"order 0", "700 1 0 0\n3 0\n2 0\n", 3, "order along u (degree + 1) is 0"},
      {"order 33", "700 1 0 0\n3 0\n40 33\n", 3, "order 33 along u: trivox evaluates orders up to 32"},
      {"fewer coefficients than the order", "700 1 0 0\n3 0\n2 3\n0 0 0 1 1\n", 3,
       "2 coefficients along u with order 3"},
      {"decreasing knots", "700 1 0 0\n3 0\n2 2\n0 1 0.5 1\n", 3, "the knots along u"},
      {"knot not a number", "700 1 0 0\n3 0\n2 2\n0 0 1 x\n", 4, "knot 4 of 4 along u"},
      {"truncated knots", "700 1 0 0\n3 0\n2 2\n0 0 1\n", 4, "the file ends within the 4 knots along u"},
      {"coefficient NaN", "700 1 0 0\n3 0\n" + bases + "0 0 0\n0 0 nan\n" + points.substr(12), 10,
       "value 3 of coefficient 1"},
      {"truncated coefficients", "700 1 0 0\n3 0\n" + bases + "0 0 0\n1 0 0\n", 10,
       "the file ends after 6 of the 24 coefficient values"},
      {"weight zero", "700 1 0 0\n3 1\n" + bases + "0 0 0 1\n1 0 0 0\n" + six_weighted, 10,
       "coefficient 1 has weight 0"},
      {"weight negative", "700 1 0 0\n3 1\n" + bases + "0 0 0 -2\n0 0 0 1\n" + six_weighted, 9,
       "coefficient 0 has weight -2"},
      {"homogeneous overflow", "700 1 0 0\n3 1\n" + bases + "1e300 0 0 1e-300\n0 0 0 1\n" + six_weighted, 9,
       "overflows"},
      {"only skipped objects", "120 1 0 0\n0 0 0 1 1 1\n", 0, "the file holds no SplineCurve"},
      {"trailing garbage", "700 1 0 0\n3 0\n" + bases + points + "junk\n", 17, "junk"},
  };
  for (const Bad& c : cases) {
    SCOPED_TRACE(c.what);
    try {
      read_g2(c.text, "bad.g2");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad.g2");
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
}

TEST(G2Reader, HugeCountsAreRefusedBeforeAllocating) {
  // 1e8 coefficients in each of three directions would overflow 64 bits when multiplied and
  // ask for petabytes; the limit (kMaxControlPoints) and the file's length refuse them
  // first, within microseconds.
  const std::string per_dir = "100000000 2\n0 0 1 1\n";
  try {
    read_g2("700 1 0 0\n3 0\n" + per_dir, "huge.g2");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the file ends within the 100000002 knots along u"), std::string::npos)
        << e.what();
  }
  // Small knot vectors whose counts multiply past the limit.
  std::string text = "700 1 0 0\n3 0\n";
  for (int d = 0; d < 3; ++d) {
    text += "1000 2\n0 0";
    for (int i = 1; i <= 998; ++i) text += " " + std::to_string(i);
    text += " 999 999\n";
  }
  try {
    read_g2(text, "many.g2");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("1000000000 coefficients together so far, above the limit of 100000000"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(read_g2("700 1 0 2000000000\n", "aux.g2"), InputError);
  EXPECT_THROW(read_g2("700 1 0 0\n2000000 0\n", "dim.g2"), InputError);
}

void expect_identical(const Model& a, const Model& b) {
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (std::size_t i = 0; i < a.patches.size(); ++i) {
    const TensorSpline& s = a.patches[i].spline;
    const TensorSpline& t = b.patches[i].spline;
    EXPECT_EQ(s.all_knots(), t.all_knots());
    EXPECT_EQ(s.point_dim(), t.point_dim());
    EXPECT_TRUE(std::equal(s.points().begin(), s.points().end(), t.points().begin(), t.points().end()));
    EXPECT_TRUE(std::equal(s.weights().begin(), s.weights().end(), t.weights().begin(), t.weights().end()));
    EXPECT_EQ(a.patches[i].header_aux, b.patches[i].header_aux);
  }
}

TEST(G2Writer, RoundTripsExactly) {
  std::ostringstream out;
  const Model m = read_g2(
      "200 1 0 4 255 0 0 255\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n" + std::string(kVolume),
      "two.g2");
  write_g2(out, m);
  const Model back = read_g2(out.str(), "back.g2");
  expect_identical(m, back);
  // The writer's layout is GoTools' own: the header, "dim rational", "n order" and knots.
  EXPECT_EQ(out.str().rfind("200 1 0 4 255 0 0 255\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0 0 0\n1 0 0\n", 0), 0u)
      << out.str();
}

// Whether some double c within 8 ulps of w * x gives c / w == x: not always, since the
// quotients of adjacent doubles may step over x.
bool homogeneous_exists(double x, double w) {
  double lo = w * x, hi = lo;
  for (int i = 0; i <= 8; ++i) {
    if (lo / w == x || hi / w == x) return true;
    lo = std::nextafter(lo, -INFINITY);
    hi = std::nextafter(hi, INFINITY);
  }
  return false;
}

TEST(G2Writer, RationalCoordinatesReadBackToTheSameDoublesWhereverOneExists) {
  // Random rational volumes with weights of every size: the homogeneous value written for x
  // is one whose quotient by w reads back as x whenever such a double exists, and is within an
  // ulp of x otherwise.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-10.0, 10.0), logw(-6.0, 6.0);
  const KnotVector kv(3, {0, 0, 0, 0.25, 1, 1, 1});
  int exact = 0, reachable = 0, total = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> pts, w;
    for (int i = 0; i < 64; ++i) {
      pts.insert(pts.end(), {U(rng), U(rng), U(rng)});
      w.push_back(std::exp(logw(rng)));
    }
    Model m{"r", {Patch{"R", 0, 0, TensorSpline({kv, kv, kv}, 3, pts, w)}}, {}};
    std::ostringstream out;
    write_g2(out, m);
    const Model back = read_g2(out.str(), "back.g2");
    const TensorSpline& t = back.patches[0].spline;
    ASSERT_TRUE(std::equal(w.begin(), w.end(), t.weights().begin(), t.weights().end()));
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double wk = w[k / 3];
      ++total;
      exact += t.points()[k] == pts[k];
      reachable += homogeneous_exists(pts[k], wk);
      EXPECT_NEAR(t.points()[k], pts[k], 2.3e-16 * std::abs(pts[k])) << k;
    }
  }
  EXPECT_EQ(exact, reachable) << "of " << total;
  EXPECT_LT(exact, total);  // the case the comment above describes does occur
}

TEST(G2Writer, ARationalModelReadFromG2RoundTripsExactly) {
  // Coordinates read from a .g2 file are quotients c / w: written again they read back
  // bit for bit (read -> write -> read gives identical knots, coefficients and weights).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-10.0, 10.0), logw(-6.0, 6.0);
  std::ostringstream text;
  text.precision(17);
  text << "700 1 0 0\n3 1\n3 3\n0 0 0 1 1 1\n3 3\n0 0 0 1 1 1\n4 3\n0 0 0 0.5 1 1 1\n";
  for (int i = 0; i < 36; ++i) {
    const double w = std::exp(logw(rng));
    text << U(rng) << ' ' << U(rng) << ' ' << U(rng) << ' ' << w << '\n';
  }
  const Model first = read_g2(text.str(), "first.g2");
  std::ostringstream out;
  write_g2(out, first);
  const Model second = read_g2(out.str(), "second.g2");
  expect_identical(first, second);
  std::ostringstream again;
  write_g2(again, second);
  EXPECT_EQ(again.str(), out.str());
}

TEST(G2Writer, PeriodicDirectionsBecomeTheUnclampedBasisTheyEvaluateAs) {
  std::mt19937 rng(3);
  const TensorSpline s = test::random_rational_spline(rng);  // periodic in v
  Model m{"p", {Patch{"P", 0, 0, s}}, {}};
  std::ostringstream out;
  write_g2(out, m);
  const Model back = read_g2(out.str(), "back.g2");
  const TensorSpline& t = back.patches[0].spline;
  EXPECT_FALSE(t.knots(1).is_periodic());
  EXPECT_EQ(t.num_ctrl(1), s.knots(1).num_basis());
  for (double u : {0.0, 1.3, 2.9, 3.0})
    for (double v : {3.0, 4.4, 6.0, 8.0})
      for (double w : {0.0, 0.5, 1.0}) {
        const std::vector<double> a = eval(s, {u, v, w}), b = eval(t, {u, v, w});
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-14) << u << ' ' << v << ' ' << w;
      }
}

TEST(G2Reader, ReadModelTakesTheExtensionOrSniffsAHeader) {
  const fs::path dir = fs::temp_directory_path() / "trivox_g2_test";
  fs::create_directories(dir);
  for (const char* name : {"volume.g2", "volume.G2", "volume.txt"}) {
    const fs::path path = dir / name;
    { std::ofstream(path) << kVolume; }
    const Model m = read_model(path);
    ASSERT_EQ(m.patches.size(), 1u) << name;
    EXPECT_EQ(m.source, path.string());
    EXPECT_EQ(model_format_of(path) == ModelFormat::kG2, std::string(name) != "volume.txt") << name;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace trivox
