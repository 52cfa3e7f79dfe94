// Helpers for the scene tests: a scratch folder per test and expectations on InputError.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "construct/construct_fixtures.h"
#include "trivox/error.h"
#include "trivox/scene/scene.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::test {

// A fresh folder under the system's temporary folder, named after the running test.
inline std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "trivox_scene_tests" /
                                    (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Parses `text` as the scene `dir/scene.json` and expects an InputError whose JSON pointer is
// `pointer` and whose message contains `fragment`.
inline void expect_scene_error(const std::string& text, const std::string& pointer, const std::string& fragment,
                               const std::filesystem::path& dir = std::filesystem::temp_directory_path()) {
  const std::filesystem::path source = dir / "scene.json";
  try {
    parse_scene(text, source);
    ADD_FAILURE() << "no error; expected one at " << pointer;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), source.string());
    EXPECT_EQ(e.where(), pointer) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(pointer), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << "expected \"" << fragment << "\" in: " << what;
  }
}

// The JSON of a curve or surface, inline.
inline nlohmann::ordered_json inline_spline(const TensorSpline& s) {
  using nlohmann::ordered_json;
  ordered_json orders = ordered_json::array(), knots = ordered_json::array(), points = ordered_json::array();
  for (int d = 0; d < s.param_dim(); ++d) {
    orders.push_back(s.knots(d).order());
    knots.push_back(std::vector<double>(s.knots(d).knots().begin(), s.knots(d).knots().end()));
  }
  for (int p = 0; p < s.total_ctrl(); ++p)
    points.push_back({s.points()[3 * p], s.points()[3 * p + 1], s.points()[3 * p + 2]});
  ordered_json j = {{"orders", orders}, {"knots", knots}, {"points", points}};
  if (s.is_rational()) j["weights"] = std::vector<double>(s.weights().begin(), s.weights().end());
  return j;
}

// A scene of one cell whose geometry is `geometry`, of one material.
inline nlohmann::ordered_json scene_with(const nlohmann::ordered_json& geometry) {
  return {{"units", "mm"},
          {"printer", "j750-hq"},
          {"materials", {{{"name", "A"}, {"rgba", {0, 0, 0, 255}}}}},
          {"cells",
           {{{"name", "c"}, {"geometry", geometry}, {"material", {{"kind", "constant"}, {"fractions", {{"A", 1}}}}}}}}};
}

// The six faces of the box [0, 1] x [0, 2] x [0, 3] as a Coons constructor's "u0" to "w1".
inline nlohmann::ordered_json coons_box_faces() {
  const auto plate = [](auto f) { return inline_spline(bilinear_plate(f)); };
  return {{"u0", plate([](double v, double w) {
             return Vec3{0, 2 * v, 3 * w};
           })},
          {"u1", plate([](double v, double w) {
             return Vec3{1, 2 * v, 3 * w};
           })},
          {"v0", plate([](double u, double w) {
             return Vec3{u, 0, 3 * w};
           })},
          {"v1", plate([](double u, double w) {
             return Vec3{u, 2, 3 * w};
           })},
          {"w0", plate([](double u, double v) {
             return Vec3{u, 2 * v, 0};
           })},
          {"w1", plate([](double u, double v) {
             return Vec3{u, 2 * v, 3};
           })}};
}

// The bytes of the file at `path`.
inline std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The message of the exception of type E that f() throws; a failure when it throws none.
template <class E, class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception of the expected type";
  return "";
}

}  // namespace trivox::test
