// Helpers for the scene tests: a scratch folder per test and expectations on InputError.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "trivox/error.h"
#include "trivox/scene/scene.h"

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

}  // namespace trivox::test
