// The corpus of broken model files under tests/data/malformed: each must be rejected with
// the right exception type, and its message must name the file, the line where the problem
// is and the rule it breaks. One test per file, so a regression names the case.
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox {
namespace {

namespace fs = std::filesystem;

struct MalformedCase {
  const char* file;
  bool unsupported;  // UnsupportedError (a valid file of a kind trivox does not read)
  int line;          // 0: the whole file (empty, nothing to read)
  const char* rule;  // a substring of the message naming the rule broken
};

// Printed in test names: the file name without its extension.
std::string case_name(const ::testing::TestParamInfo<MalformedCase>& info) {
  std::string name = fs::path(info.param.file).stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

class MalformedFile : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedFile, IsRejectedNamingFileLineAndRule) {
  const MalformedCase& c = GetParam();
  const fs::path path = fs::path(TRIVOX_TEST_DATA_DIR) / "malformed" / c.file;
  ASSERT_TRUE(fs::exists(path)) << path;
  try {
    read_model(path);
    FAIL() << c.file << " was read without error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(dynamic_cast<const UnsupportedError*>(&e) != nullptr, c.unsupported) << what;
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.line(), c.line) << what;
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    if (c.line > 0) {
      EXPECT_NE(what.find(path.string() + ":" + std::to_string(c.line) + ":"), std::string::npos) << what;
    }
    EXPECT_NE(what.find(c.rule), std::string::npos) << "rule '" << c.rule << "' not in: " << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, MalformedFile,
    ::testing::Values(
        // IRIT text
        MalformedCase{"itd_knots_decreasing.itd", false, 3, "knots decrease"},
        MalformedCase{"itd_knot_count.itd", false, 3, "need 5 knots"},
        MalformedCase{"itd_multiplicity_above_order.itd", false, 3, "multiplicity 3, above the order 2"},
        MalformedCase{"itd_weight_zero.itd", false, 5, "weights must be > 0"},
        MalformedCase{"itd_nan_coordinate.itd", false, 4, "'nan' is not finite"},
        MalformedCase{"itd_inf_knot.itd", false, 3, "'inf' is not finite"},
        MalformedCase{"itd_too_few_points.itd", false, 6, "3 control points declared, found only 2"},
        MalformedCase{"itd_too_many_points.itd", false, 6, "more control points than the 2 declared"},
        MalformedCase{"itd_truncated.itd", false, 4, "unexpected end of file"},
        MalformedCase{"itd_unmatched_close.itd", false, 4, "unmatched ']'"},
        MalformedCase{"itd_unclosed_object.itd", false, 5, "opened at line 1 is never closed"},
        MalformedCase{"itd_unknown_point_type.itd", false, 2, "point type must be E1..E9"},
        MalformedCase{"itd_huge_sizes.itd", false, 2, "above the limit of 100000000"},
        MalformedCase{"itd_non_numeric.itd", false, 5, "'one' is not a number"},
        MalformedCase{"itd_empty.itd", false, 0, "file is empty"},
        MalformedCase{"itd_order_too_high.itd", false, 2, "order along u is 33, outside 1..32"},
        MalformedCase{"itd_point_arity.itd", false, 4, "has 2 numbers; point type E3 holds 3"},
        MalformedCase{"itd_non_integer_count.itd", false, 2, "must be an integer, found '2.5'"},
        MalformedCase{"itd_unclosed_string.itd", false, 1, "string opened here is never closed"},
        MalformedCase{"itd_binary.itd", false, 2, "control character 0x01"},
        MalformedCase{"itd_no_geometry.itd", false, 0, "no CURVE, SURFACE or TRIVAR"},
        MalformedCase{"itd_missing_knot_vector.itd", false, 3, "expected the u knot vector"},
        MalformedCase{"itd_stray_word.itd", false, 3, "unexpected 'stray'"},
        // G+Smo XML
        MalformedCase{"xml_thbspline.xml", true, 3, "THBSpline3 is a hierarchical"},
        MalformedCase{"xml_unknown_type.xml", true, 3, "Geometry type 'TensorBezier3' is not supported"},
        MalformedCase{"xml_bad_base64.xml", false, 15, "character '*' is not base64"},
        MalformedCase{"xml_base64_length.xml", false, 15, "12 bytes is not a whole number of 8-byte values"},
        MalformedCase{"xml_unknown_format.xml", false, 15, "unknown number format 'B64Float16'"},
        MalformedCase{"xml_syntax.xml", false, 6, "XML syntax error"},
        MalformedCase{"xml_coefs_count.xml", false, 15, "holds 21 numbers; 8 basis functions times geoDim 3 need 24"},
        MalformedCase{"xml_missing_degree.xml", false, 12, "no degree attribute"},
        MalformedCase{"xml_weight_negative.xml", false, 8, "weights must be > 0"},
        MalformedCase{"xml_fraction_zero.xml", false, 17, "'1/0' has a zero denominator"},
        MalformedCase{"xml_multipatch_missing_id.xml", false, 18, "no <Geometry id=\"1\"> exists"},
        MalformedCase{"xml_child_count.xml", false, 4, "needs 3 child <Basis> elements"},
        MalformedCase{"xml_empty.xml", false, 0, "file is empty"},
        MalformedCase{"xml_knots_decreasing.xml", false, 9, "knots decrease"},
        MalformedCase{"xml_nan_coefs.xml", false, 18, "'NaN' is not finite"},
        MalformedCase{"xml_non_numeric.xml", false, 16, "'abc' is not a number"},
        MalformedCase{"xml_wrong_root.xml", false, 2, "root element must be <xml>"},
        // Sizes given by mode="uniform" csize: refused before anything is allocated for them,
        // without overflow (67108864 x 67108864 x 4096 functions is 2^64).
        MalformedCase{"xml_uniform_overflow.xml", false, 6, "but <coefs> holds only 0 numbers"},
        MalformedCase{"xml_uniform_huge.xml", false, 6, "holds only 24 numbers"},
        // GoTools .g2
        MalformedCase{"g2_truncated.g2", false, 11, "the file ends after 9 of the 24 coefficient values"},
        MalformedCase{"g2_weight_zero.g2", false, 11, "coefficient 2 has weight 0"},
        MalformedCase{"g2_unknown_class.g2", false, 1, "707 is not a GoTools class number"},
        MalformedCase{"g2_huge_counts.g2", false, 4, "the file ends within the 100000002 knots along u"},
        MalformedCase{"g2_order_too_high.g2", false, 3, "order 40 along u: trivox evaluates orders up to 32"},
        MalformedCase{"g2_knots_decreasing.g2", false, 3, "the knots along u"}),
    case_name);

TEST(MalformedInput, EveryCorpusFileHasACase) {
  // A file added to the corpus without a row above would never be checked.
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(TRIVOX_TEST_DATA_DIR) / "malformed"))
    files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 48);
}

TEST(MalformedInput, MissingFileIsAnIoError) {
  const fs::path missing = fs::path(TRIVOX_TEST_DATA_DIR) / "malformed" / "no_such_file.itd";
  try {
    read_model(missing);
    FAIL() << "a missing file was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
}

TEST(MalformedInput, DirectoryIsAnIoError) {
  EXPECT_THROW(read_model(fs::path(TRIVOX_TEST_DATA_DIR) / "malformed"), IoError);
}

TEST(MalformedInput, UnknownFormatIsNamed) {
  const fs::path path = fs::temp_directory_path() / "trivox_malformed_unknown_format.stl";
  {
    std::ofstream out(path);
    out << "solid cube\nendsolid\n";
  }
  try {
    read_model(path);
    FAIL() << "an STL file was read as a model";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown model format '.stl'"), std::string::npos) << e.what();
  }
  fs::remove(path);
}

TEST(MalformedInput, ReadersReturnNoPartialModel) {
  // The first object is fine, the second is not: the whole read fails.
  const std::string text = "[OBJECT A [CURVE BEZIER 2 E1 [0] [1]]]\n[OBJECT B [CURVE BEZIER 2 E1 [0] [x]]]\n";
  EXPECT_THROW(read_itd(text, "two.itd"), InputError);
}

TEST(MalformedInput, DeepNestingIsAnErrorNotACrash) {
  std::string text;
  for (int i = 0; i < 5000; ++i) text += "[OBJECT A ";
  text += "[CURVE BEZIER 2 E1 [0] [1]]";
  for (int i = 0; i < 5000; ++i) text += "]";
  try {
    read_itd(text, "deep.itd");
    FAIL() << "5000 nested objects were read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nested more than"), std::string::npos) << e.what();
  }
  // Deeply nested brackets inside a skipped group are consumed without recursion.
  std::string skipped = "[OBJECT A [ATTRS ";
  for (int i = 0; i < 100000; ++i) skipped += "[";
  for (int i = 0; i < 100000; ++i) skipped += "]";
  skipped += "] [CURVE BEZIER 2 E1 [0] [1]]]";
  EXPECT_EQ(read_itd(skipped, "deep_skip.itd").patches.size(), 1u);
}

TEST(MalformedInput, HugeIrregularNumbersAreRejected) {
  EXPECT_THROW(read_itd("[OBJECT A [CURVE BEZIER 2 E1 [0] [1e999]]]", "big.itd"), InputError);
  EXPECT_THROW(read_itd("[OBJECT A [CURVE BSPLINE 99999999999999999999 2 E1]]", "count.itd"), InputError);
  EXPECT_THROW(read_itd("[OBJECT A [CURVE BSPLINE -3 2 E1]]", "negative.itd"), InputError);
}

}  // namespace
}  // namespace trivox
