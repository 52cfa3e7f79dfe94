// IRIT text reader and writer on small hand-written files whose values are computed by
// hand: a periodic curve, a rational trivariate, a file mixing every kind of object the
// reader reads or skips; then write_itd round trips and read_model's dispatch.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

fs::path model_path(const char* name) { return fs::path(TRIVOX_TEST_DATA_DIR) / "models" / name; }

std::vector<double> eval(const TensorSpline& s, std::vector<double> t) {
  std::vector<double> out(static_cast<std::size_t>(s.point_dim()));
  s.evaluate(t, out);
  return out;
}

TEST(ItdReader, PeriodicCurveWrapsItsControlPoints) {
  const Model m = read_model(model_path("periodic_curve.itd"));
  ASSERT_EQ(m.patches.size(), 1u);
  const Patch& p = m.patches[0];
  EXPECT_EQ(p.name, "LOOP");
  EXPECT_EQ(p.source_line, 2);
  const TensorSpline& s = p.spline;
  ASSERT_EQ(s.param_dim(), 1);
  EXPECT_EQ(s.point_dim(), 2);
  EXPECT_FALSE(s.is_rational());
  const KnotVector& kv = s.knots(0);
  EXPECT_TRUE(kv.is_periodic());
  EXPECT_EQ(kv.order(), 3);
  EXPECT_EQ(kv.num_ctrl(), 4);  // the 4 distinct points; 6 basis functions wrap onto them
  EXPECT_EQ(kv.num_basis(), 6);
  EXPECT_EQ(s.lo(0), 2.0);  // domain [t_{k-1}, t_{n+k-1}] of the 9 knots 0..8
  EXPECT_EQ(s.hi(0), 6.0);
  // Uniform quadratic: at a knot the curve is the midpoint of two control points, at a span
  // midpoint the 1/8, 6/8, 1/8 blend of three; P4 = P0 and P5 = P1 close the loop.
  EXPECT_EQ(eval(s, {2.0}), (std::vector<double>{0.5, 0.0}));
  EXPECT_EQ(eval(s, {3.0}), (std::vector<double>{1.0, 0.5}));
  EXPECT_EQ(eval(s, {4.5}), (std::vector<double>{0.125, 0.875}));
  const std::vector<double> end = eval(s, {6.0});
  EXPECT_NEAR(end[0], 0.5, 1e-15);
  EXPECT_NEAR(end[1], 0.0, 1e-15);
}

TEST(ItdReader, RationalPointsAreWeightFirstAndPremultiplied) {
  const Model m = read_model(model_path("rational_trivar.itd"));
  ASSERT_EQ(m.patches.size(), 1u);
  const TensorSpline& s = m.patches[0].spline;
  EXPECT_EQ(m.patches[0].name, "WCUBE");  // attributes, even with brackets in strings, skipped
  ASSERT_EQ(s.param_dim(), 3);
  ASSERT_TRUE(s.is_rational());
  EXPECT_EQ(s.knots(2).hi(), 2.0);
  // [w, w*x, w*y, w*z] -> point (x, y, z), weight w.
  const std::array<double, 8> w = {1, 2, 0.5, 4, 1, 1, 2, 0.25};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        EXPECT_EQ(s.weight(i, j, k), w[static_cast<std::size_t>(i + 2 * j + 4 * k)]);
        const auto p = s.point(i, j, k);
        EXPECT_EQ(p[0], i);
        EXPECT_EQ(p[1], j);
        EXPECT_EQ(p[2], k);
      }
  // Trilinear at the centre: every basis function is 1/8, so the point is sum(w P) / sum(w).
  const std::vector<double> c = eval(s, {0.5, 0.5, 1.0});
  EXPECT_NEAR(c[0], 7.25 / 11.75, 1e-15);
  EXPECT_NEAR(c[1], 6.75 / 11.75, 1e-15);
  EXPECT_NEAR(c[2], 4.25 / 11.75, 1e-15);
}

TEST(ItdReader, ReadsGeometryAndSkipsEverythingElse) {
  const Model m = read_model(model_path("mixed_objects.itd"));
  // Read: the Bezier trivariate, the curve of an object named NONE, the surface of an object
  // without a name, a TRIMSRF's surface and a MODEL's two surfaces. Skipped: matrices,
  // polygons (with point attributes), numbers, an animation attribute holding a curve, the
  // trimming curves and the MODEL's segments.
  ASSERT_EQ(m.patches.size(), 6u);
  const std::array<const char*, 6> names = {"BOX", "GROUP", "patch", "TRIMMED", "SHELL #0", "SHELL #1"};
  const std::array<int, 6> lines = {20, 26, 35, 42, 51, 57};
  const std::array<int, 6> dims = {3, 1, 2, 2, 2, 2};
  for (std::size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(m.patches[i].name, names[i]);
    EXPECT_EQ(m.patches[i].source_line, lines[i]);
    EXPECT_EQ(m.patches[i].id, static_cast<int>(i));
    EXPECT_EQ(m.patches[i].spline.param_dim(), dims[i]);
  }
  EXPECT_EQ(m.volume_indices(), std::vector<int>{0});

  const TensorSpline& box = m.patches[0].spline;  // Bezier: order = point count, knots 0 0 1 1
  for (int d = 0; d < 3; ++d) EXPECT_EQ(box.knots(d), KnotVector::bezier(2));
  EXPECT_EQ(box.point(1, 1, 1)[0], 1.0);

  const TensorSpline& curve = m.patches[1].spline;  // [[weight 3] 0.5]: attribute skipped
  EXPECT_EQ(curve.point_dim(), 1);
  EXPECT_EQ(curve.point(1)[0], 0.5);
  EXPECT_EQ(curve.knots(0).order(), 3);

  const TensorSpline& rational = m.patches[5].spline;
  ASSERT_TRUE(rational.is_rational());
  EXPECT_EQ(rational.weight(1, 1), 2.0);
  EXPECT_EQ(rational.point(1, 1)[1], 1.0);
}

TEST(ItdReader, KeywordsAreCaseInsensitiveAndGeometryMayStandAlone) {
  const Model m = read_itd(
      "[curve bezier 2 e1 [0] [1]]\n[object Low [surface bspline 2 2 2 2 p1\n"
      "  [kv 0 0 1 1] [kvp 0 1 2 3 4]\n  [1 0] [1 1] [2 2] [2 4]]]\n",
      "lower.itd");
  ASSERT_EQ(m.patches.size(), 2u);
  EXPECT_EQ(m.patches[0].name, "patch");
  EXPECT_EQ(m.patches[1].name, "Low");
  EXPECT_EQ(m.patches[1].source_line, 2);
  EXPECT_TRUE(m.patches[1].spline.knots(1).is_periodic());
  EXPECT_EQ(m.patches[1].spline.point(1, 1)[0], 2.0);  // [2 4]: w = 2, value 4 / 2
}

TEST(ItdReader, PowerBasisIsUnsupported) {
  try {
    read_itd("[OBJECT P\n  [CURVE POWER 2 E1 [0] [1]]]", "power.itd");
    FAIL() << "a power-basis curve was read";
  } catch (const UnsupportedError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("POWER basis is not supported"), std::string::npos) << e.what();
  }
}

// Write, read back and compare; rational coordinates are written as w*x and divided again.
void expect_round_trip(const Model& m) {
  std::ostringstream out;
  write_itd(out, m);
  const Model back = read_itd(out.str(), "round trip");
  ASSERT_EQ(back.patches.size(), m.patches.size());
  for (std::size_t i = 0; i < m.patches.size(); ++i) {
    const TensorSpline& a = m.patches[i].spline;
    const TensorSpline& b = back.patches[i].spline;
    EXPECT_EQ(a.all_knots(), b.all_knots());
    EXPECT_EQ(a.point_dim(), b.point_dim());
    EXPECT_TRUE(std::equal(a.weights().begin(), a.weights().end(), b.weights().begin(), b.weights().end()));
    ASSERT_EQ(a.points().size(), b.points().size());
    for (std::size_t k = 0; k < a.points().size(); ++k) {
      if (a.is_rational())
        EXPECT_NEAR(b.points()[k], a.points()[k], 1e-15 * std::abs(a.points()[k]));
      else
        EXPECT_EQ(b.points()[k], a.points()[k]);
    }
  }
}

TEST(ItdWriter, RoundTripsEveryFixture) {
  for (const char* name : {"periodic_curve.itd", "rational_trivar.itd", "mixed_objects.itd", "uniform_fractions.xml",
                           "nurbs_base64.xml", "multipatch_ids.xml"}) {
    SCOPED_TRACE(name);
    expect_round_trip(read_model(model_path(name)));
  }
}

TEST(ItdWriter, RoundTripsDigitsThatNeedSeventeenPlaces) {
  const double third = 1.0 / 3.0, tiny = 4.898587196589413e-17, big = 1.2345678901234567e99;
  const TensorSpline s({KnotVector(2, {0, 0, third, 1, 1})}, 2, {third, tiny, big, -third, 0.1, 0.7});
  expect_round_trip(Model{"digits", {Patch{"D", 0, 0, s}}, {}});
  const TensorSpline r({KnotVector(2, {0, 0, 1, 1})}, 3, {third, tiny, 0.1, 0.2, 0.3, 0.7}, {0.7, 3.0});
  expect_round_trip(Model{"digits", {Patch{"R", 0, 0, r}}, {}});
}

// Numbers beyond kMaxModelNumber overflow a volume's derivatives and det J: refused where they
// are read, with the line and the reason, as the .g2 and G+Smo readers refuse them.
TEST(ItdReader, RefusesANumberThatOverflows) {
  const std::string text = "[OBJECT C\n  [CURVE BSPLINE 2 2 E1\n    [KV 0 0 1 1]\n    [0]\n    [1e300]\n  ]\n]\n";
  try {
    read_itd(text, "huge.itd");
    FAIL() << "a coordinate of 1e300 was read";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("huge.itd:5"), std::string::npos) << what;
    EXPECT_NE(what.find("'1e300' overflows"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(
      read_itd("[OBJECT C\n  [CURVE BSPLINE 2 2 E1\n    [KV 0 0 1 1]\n    [0]\n    [1e99]\n  ]\n]\n", "big.itd"));
}

TEST(ItdWriter, WritesKvpWeightFirstAndSingleWordNames) {
  Model m = read_model(model_path("rational_trivar.itd"));
  const Model periodic = read_model(model_path("periodic_curve.itd"));
  m.patches.push_back(periodic.patches[0]);
  m.patches[0].name = "Geometry id=3 [x]";
  std::ostringstream out;
  write_itd(out, m);
  const std::string text = out.str();
  EXPECT_NE(text.find("[OBJECT Geometry_id=3__x_\n"), std::string::npos) << text;
  EXPECT_NE(text.find("[TRIVAR BSPLINE 2 2 2 2 2 2 P3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("[2 2 0 0]"), std::string::npos) << text;  // w = 2, point (1, 0, 0)
  EXPECT_NE(text.find("[CURVE BSPLINE 4 3 E2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("[KVP 0 1 2 3 4 5 6 7 8]"), std::string::npos) << text;
  EXPECT_EQ(read_itd(text, "names").patches[0].name, "Geometry_id=3__x_");
}

TEST(ItdWriter, RejectsPointsIritCannotHold) {
  const TensorSpline s({KnotVector::bezier(2)}, 10, std::vector<double>(20, 1.0));
  std::ostringstream out;
  EXPECT_THROW(write_itd(out, Model{"wide", {Patch{"W", 0, 0, s}}, {}}), ModelError);
  EXPECT_TRUE(out.str().empty());  // nothing half-written
}

TEST(ItdWriter, FailingStreamIsAnIoError) {
  std::ostringstream out;
  out.setstate(std::ios::badbit);
  EXPECT_THROW(write_itd(out, read_model(model_path("periodic_curve.itd"))), IoError);
}

TEST(ItdModelFile, ReadModelPicksTheReaderByExtensionThenContent) {
  const fs::path dir = fs::temp_directory_path() / "trivox_itd_test";
  fs::create_directories(dir);
  const std::string itd = "[OBJECT C [CURVE BEZIER 2 E1 [0] [1]]]\n";
  std::ifstream xml_in(model_path("multipatch_ids.xml"));
  const std::string xml((std::istreambuf_iterator<char>(xml_in)), std::istreambuf_iterator<char>());
  const auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  EXPECT_EQ(read_model(write("a.ITD", itd)).patches[0].name, "C");
  EXPECT_EQ(read_model(write("b.dat", itd)).patches[0].name, "C");                 // sniffed: '['
  EXPECT_EQ(read_model(write("c.gismo", xml)).patches[0].name, "Geometry id=12");  // sniffed: '<'
  EXPECT_EQ(read_model(write("d.xml", xml)).source, (dir / "d.xml").string());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace trivox
