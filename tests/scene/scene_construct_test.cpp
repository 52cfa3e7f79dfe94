// Constructed geometry in scene files: each constructor builds the same volume as the
// library call, surfaces and curves come inline or from model files, and every wrong field
// fails naming its JSON pointer.
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "construct/construct_fixtures.h"
#include "scene/scene_test_util.h"
#include "support/test_support.h"
#include "trivox/construct/coons.h"
#include "trivox/construct/extrude.h"
#include "trivox/construct/revolve.h"
#include "trivox/construct/shell.h"
#include "trivox/construct/sweep.h"
#include "trivox/construct/untangle.h"
#include "trivox/io/model.h"
#include "trivox/scene/scene.h"
#include "trivox/spline/jacobian_check.h"

namespace trivox {
namespace {

using nlohmann::ordered_json;
using test::expect_scene_error;
using test::inline_spline;
using test::scene_with;

Volume read_one(const ordered_json& geometry) {
  const Scene scene = parse_scene(scene_with(geometry).dump(), std::filesystem::temp_directory_path() / "scene.json");
  EXPECT_EQ(scene.cells.size(), 1u);
  return scene.cells.front().volume;
}

void expect_same(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.spline().total_ctrl(), b.spline().total_ctrl());
  for (std::size_t i = 0; i < a.spline().points().size(); ++i)
    EXPECT_EQ(a.spline().points()[i], b.spline().points()[i]);
  ASSERT_EQ(a.spline().weights().size(), b.spline().weights().size());
  for (std::size_t i = 0; i < a.spline().weights().size(); ++i)
    EXPECT_EQ(a.spline().weights()[i], b.spline().weights()[i]);
}

const TensorSpline kPlate = test::bilinear_plate([](double a, double b) { return Vec3{10 + 10 * a, 0, 5 * b}; });
const TensorSpline kDisc = test::rational_disc({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 2);

TEST(SceneConstruct, EachConstructorBuildsWhatTheLibraryBuilds) {
  expect_same(read_one({{"extrude", {{"surface", inline_spline(kPlate)}, {"vector_mm", {0, 4, 0}}}}}),
              extrude(kPlate, {Vec3{0, 4, 0}}).volume);
  const TensorSpline moved = kPlate.transformed([](std::span<double> p) { p[1] += 3; });
  expect_same(read_one({{"ruled", {{"from", inline_spline(kPlate)}, {"to", inline_spline(moved)}}}}),
              ruled(kPlate, moved).volume);
  RevolveParams rp{{1, 0, 0}, {0, 0, 2}, 270};
  rp.angle_direction = 0;
  expect_same(read_one({{"revolve",
                         {{"profile", inline_spline(kPlate)},
                          {"axis_point_mm", {1, 0, 0}},
                          {"axis_dir", {0, 0, 2}},
                          {"angle_deg", 270},
                          {"angle_param", "u"}}}}),
              revolve(kPlate, rp).volume);
  const TensorSpline path = test::circle_curve({0, 0, 0}, 15);
  SweepParams sp;
  sp.twist_deg = 30;
  sp.stations = 12;
  expect_same(
      read_one(
          {{"sweep",
            {{"section", inline_spline(kDisc)}, {"path", inline_spline(path)}, {"twist_deg", 30}, {"stations", 12}}}}),
      sweep(kDisc, path, sp).volume);
  ShellParams shp;
  shp.thickness_mm = 0.5;
  shp.side = ShellSide::kCentred;
  expect_same(read_one({{"shell", {{"surface", inline_spline(kPlate)}, {"thickness_mm", 0.5}, {"side", "centred"}}}}),
              thick_shell(kPlate, shp).volume);
  // Coons from the faces of a box.
  const ordered_json faces = test::coons_box_faces();
  const Volume box = read_one({{"coons", faces}});
  EXPECT_LE(norm(box.evaluate({0.25, 0.5, 0.75}) - Vec3{0.25, 1, 2.25}), 1e-14);
}

TEST(SceneConstruct, SurfacesAndCurvesFromModelFiles) {
  const auto dir = test::scratch_dir();
  Model m;
  m.patches.push_back({"PROFILE", 0, 0, kPlate});
  m.patches.push_back({"PATH", 1, 0, TensorSpline({KnotVector::bezier(2)}, 3, {0, 0, 0, 0, 0, 20})});
  m.patches.push_back({"SECTION", 2, 0, kDisc});
  std::ofstream out(dir / "parts.itd");
  write_itd(out, m);
  out.close();
  ordered_json scene =
      scene_with({{"revolve", {{"profile", {{"file", "parts.itd"}, {"patch", 0}}}, {"angle_deg", 90}}}});
  Scene s = parse_scene(scene.dump(), dir / "scene.json");
  expect_same(s.cells[0].volume, revolve(kPlate, {{0, 0, 0}, {0, 0, 1}, 90}).volume);
  scene["cells"][0]["geometry"] = {
      {"sweep", {{"section", {{"file", "parts.itd"}, {"patch", 1}}}, {"path", {{"file", "parts.itd"}}}}}};
  s = parse_scene(scene.dump(), dir / "scene.json");
  EXPECT_LE(norm(s.cells[0].volume.evaluate({0.5, 0.5, 1}) - Vec3{0, 0, 20}), 1e-12);
  // Two surfaces in the file: "patch" is needed; a file without curves cannot give a path.
  scene["cells"][0]["geometry"]["sweep"]["section"] = {{"file", "parts.itd"}};
  expect_scene_error(scene.dump(), "/cells/0/geometry/sweep/section", "holds 2 surfaces", dir);
  scene["cells"][0]["geometry"] = {
      {"extrude", {{"surface", {{"file", "parts.itd"}, {"patch", 2}}}, {"vector_mm", {0, 0, 1}}}}};
  expect_scene_error(scene.dump(), "/cells/0/geometry/extrude/surface/patch", "outside [0, 1]", dir);
}

TEST(SceneConstruct, ErrorsNameTheField) {
  const ordered_json plate = inline_spline(kPlate);
  expect_scene_error(scene_with({{"revolve", {{"profile", plate}, {"angle_deg", 400}}}}).dump(),
                     "/cells/0/geometry/revolve/angle_deg", "not in (0, 360]");
  expect_scene_error(scene_with({{"revolve", {{"profile", plate}, {"axis", {0, 0, 1}}}}}).dump(),
                     "/cells/0/geometry/revolve/axis", "unknown key \"axis\"");
  expect_scene_error(scene_with({{"revolve", {{"profile", plate}, {"axis_dir", {0, 0, 0}}}}}).dump(),
                     "/cells/0/geometry/revolve/axis_dir", "the vector is zero");
  expect_scene_error(scene_with({{"revolve", {{"profile", plate}}}, {"file", "x.itd"}}).dump(), "/cells/0/geometry",
                     "exactly one key");
  expect_scene_error(scene_with({{"extrude", {{"surface", plate}}}}).dump(), "/cells/0/geometry/extrude",
                     "\"vector_mm\"");
  expect_scene_error(scene_with({{"shell", {{"surface", plate}, {"thickness_mm", -1}}}}).dump(),
                     "/cells/0/geometry/shell/thickness_mm", "not > 0");
  expect_scene_error(scene_with({{"shell", {{"surface", plate}, {"thickness_mm", 1}, {"side", "up"}}}}).dump(),
                     "/cells/0/geometry/shell/side", "\"centred\"");
  ordered_json curve_as_surface = plate;
  curve_as_surface["orders"] = {2};
  expect_scene_error(scene_with({{"extrude", {{"surface", curve_as_surface}, {"vector_mm", {0, 1, 0}}}}}).dump(),
                     "/cells/0/geometry/extrude/surface/orders", "");
  // A section off its plane: the constructor's rule, reported at the constructor.
  const TensorSpline lifted = kDisc.transformed([](std::span<double> p) { p[2] += 1; });
  expect_scene_error(
      scene_with({{"sweep", {{"section", inline_spline(lifted)}, {"path", inline_spline(test::circle_curve({}, 9))}}}})
          .dump(),
      "/cells/0/geometry/sweep", "plane z = 0");
  // Coons faces that do not meet: the faces and the edge are named.
  const auto face = [](auto f) { return inline_spline(test::bilinear_plate(f)); };
  ordered_json faces = {{"u0", face([](double v, double w) {
                           return Vec3{0, v, w};
                         })},
                        {"u1", face([](double v, double w) {
                           return Vec3{1, v, w};
                         })},
                        {"v0", face([](double u, double w) {
                           return Vec3{u, 0, w};
                         })},
                        {"v1", face([](double u, double w) {
                           return Vec3{u, 1, w};
                         })},
                        {"w0", face([](double u, double v) {
                           return Vec3{u, v, 0};
                         })},
                        {"w1", face([](double u, double v) {
                           return Vec3{u, v, 1.5};
                         })}};
  expect_scene_error(scene_with({{"coons", faces}}).dump(), "/cells/0/geometry/coons",
                     "faces u0 and w1 do not share their edge (u=0, w=1)");
  faces.erase("w1");
  expect_scene_error(scene_with({{"coons", faces}}).dump(), "/cells/0/geometry/coons", "\"w1\"");
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::filesystem::path kDocs = std::filesystem::path(TRIVOX_EXAMPLES_DIR).parent_path() / "docs";

TEST(SceneConstruct, DocumentationExamplesBuild) {
  const std::string doc = read_text(kDocs / "SCENE.md");
  std::set<std::string> built;
  const std::string open = "```json\n", close = "```";
  for (std::size_t at = doc.find(open); at != std::string::npos; at = doc.find(open, at)) {
    const std::size_t body = at + open.size(), end = doc.find(close, body);
    ASSERT_NE(end, std::string::npos);
    const ordered_json j = ordered_json::parse(doc.substr(body, end - body));
    at = end + close.size();
    if (j.size() != 1 || j.contains("cells") || j.contains("kind")) continue;
    SCOPED_TRACE(j.dump().substr(0, 200));
    const Volume v = read_one(j);
    EXPECT_NE(check_jacobian(v).classification, JacobianClass::kFolded);
    built.insert(j.begin().key());
  }
  EXPECT_EQ(built, (std::set<std::string>{"extrude", "ruled", "revolve", "sweep", "coons", "shell"}));
}

// The schema's constructors and their keys are the reader's: an unknown key is rejected with
// the list of keys the reader allows, which must be the schema's.
TEST(SceneConstruct, SchemaAgreesWithTheReader) {
  const ordered_json schema = ordered_json::parse(read_text(kDocs / "scene.schema.json"));
  const ordered_json& list = schema.at("$defs").at("constructedGeometry").at("oneOf");
  ASSERT_EQ(list.size(), 6u);
  for (const ordered_json& entry : list) {
    const std::string name = entry.at("required").at(0).get<std::string>();
    SCOPED_TRACE(name);
    std::string expected;
    for (const auto& [key, value] : entry.at("properties").at(name).at("properties").items())
      expected += (expected.empty() ? "\"" : ", \"") + key + "\"";
    try {
      read_one({{name, {{"no_such_key", 1}}}});
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the keys allowed here are " + expected), std::string::npos) << e.what();
    }
  }
}

TEST(SceneConstruct, CoonsFacesInAnyOrder) {
  const auto plate = [](auto f) { return inline_spline(test::bilinear_plate(f)); };
  // The faces of a 1 x 2 x 3 box, shuffled and with some parameters swapped.
  const ordered_json shuffled = {plate([](double u, double v) {
                                   return Vec3{u, 2 * v, 3};
                                 }),
                                 plate([](double w, double v) {
                                   return Vec3{0, 2 * v, 3 * w};
                                 }),
                                 plate([](double u, double w) {
                                   return Vec3{u, 0, 3 * w};
                                 }),
                                 plate([](double u, double v) {
                                   return Vec3{u, 2 * v, 0};
                                 }),
                                 plate([](double v, double w) {
                                   return Vec3{1, 2 * v, 3 * w};
                                 }),
                                 plate([](double w, double u) {
                                   return Vec3{u, 2, 3 * w};
                                 })};
  const Volume box = read_one({{"coons", {{"faces", shuffled}}}});
  EXPECT_NE(check_jacobian(box).classification, JacobianClass::kFolded);
  const Box3 b = box.bounds();
  EXPECT_LE(norm(b.lo - Vec3{0, 0, 0}) + norm(b.hi - Vec3{1, 2, 3}), 1e-14);
  expect_scene_error(scene_with({{"coons", {{"faces", shuffled}, {"u0", shuffled[1]}}}}).dump(),
                     "/cells/0/geometry/coons/u0", "not both");
  ordered_json five = shuffled;
  five.erase(five.size() - 1);
  expect_scene_error(scene_with({{"coons", {{"faces", five}}}}).dump(), "/cells/0/geometry/coons/faces",
                     "array of 6 elements");
}

TEST(SceneConstruct, CoonsUntangleIsTheLibrarysAndChecksItsKeys) {
  // A box whose top bulges: the untangled volume is the library's untangle() of the Coons
  // volume, point for point.
  const auto plate = [](auto f) { return test::bilinear_plate(f); };
  std::array<TensorSpline, 6> faces{plate([](double v, double w) {
                                      return Vec3{0, 4 * v, 3 * w};
                                    }),
                                    plate([](double v, double w) {
                                      return Vec3{5, 4 * v, 3 * w};
                                    }),
                                    plate([](double u, double w) {
                                      return Vec3{5 * u, 0, 3 * w};
                                    }),
                                    plate([](double u, double w) {
                                      return Vec3{5 * u, 4, 3 * w};
                                    }),
                                    plate([](double u, double v) {
                                      return Vec3{5 * u, 4 * v, 0};
                                    }),
                                    plate([](double u, double v) {
                                      return Vec3{5 * u, 4 * v, 3};
                                    })};
  ordered_json coons_json;
  for (int f = 0; f < 6; ++f) coons_json[coons_face_name(f)] = inline_spline(faces[static_cast<std::size_t>(f)]);
  UntangleParams p;
  p.knots_per_span = 2;
  p.iterations = 10;
  p.samples_per_span = 2;
  p.target_relative = 0.5;
  ordered_json with = coons_json;
  with["untangle"] = {{"knots_per_span", 2}, {"iterations", 10}, {"samples_per_span", 2}, {"target", 0.5}};
  const Volume v = read_one({{"coons", with}});
  expect_same(v, Volume(untangle(coons(faces).volume.spline(), p).spline));
  EXPECT_EQ(v.spline().num_ctrl(0), 4);  // two knots inserted into the single span
  with["untangle"] = {{"knots", 2}};
  expect_scene_error(scene_with({{"coons", with}}).dump(), "/cells/0/geometry/coons/untangle/knots",
                     "unknown key \"knots\"");
  with["untangle"] = {{"target", 1.5}};
  expect_scene_error(scene_with({{"coons", with}}).dump(), "/cells/0/geometry/coons/untangle/target", "> 0 and < 1");
  with["untangle"] = {{"knots_per_span", 9}};
  expect_scene_error(scene_with({{"coons", with}}).dump(), "/cells/0/geometry/coons/untangle/knots_per_span", "");
}

TEST(SceneConstruct, CoonsVolumeOfTheSharedDuckFolds) {
  const auto dir = test::shared_data_dir();
  if (dir.empty()) GTEST_SKIP() << test::shared_data_missing_message();
  const std::string file = (dir / "surfaces" / "duck_brep.xml").string();
  expect_scene_error(scene_with({{"coons", {{"faces", {{"file", file}}}}}}).dump(), "/cells/0/geometry/coons",
                     "folds over itself");
  const Volume duck = read_one({{"coons", {{"faces", {{"file", file}}}, {"allow_fold", true}}}});
  EXPECT_EQ(check_jacobian(duck).classification, JacobianClass::kFolded);
}

TEST(SceneConstruct, FoldedVolumesAreErrorsUnlessAllowed) {
  const ordered_json bottom = inline_spline(test::bilinear_plate([](double a, double b) {
    return Vec3{10 * a, 10 * b, 0};
  }));
  const ordered_json top = inline_spline(test::bilinear_plate([](double a, double b) {
    return Vec3{10 - 10 * a, 10 * b, 4};
  }));
  expect_scene_error(scene_with({{"ruled", {{"from", bottom}, {"to", top}}}}).dump(), "/cells/0/geometry/ruled",
                     "folds over itself (folded: det J");
  const Volume v = read_one({{"ruled", {{"from", bottom}, {"to", top}, {"allow_fold", true}}}});
  EXPECT_EQ(v.spline().total_ctrl(), 8);
}

}  // namespace
}  // namespace trivox
