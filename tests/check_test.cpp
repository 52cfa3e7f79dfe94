// The invariant checks (src/check.h): in the builds that compile them in (sanitizers, Debug),
// a failed check names the expression and both operands and aborts; elsewhere they cost
// nothing and do not evaluate their operands.
#include "check.h"

#include <gtest/gtest.h>

namespace trivox {
namespace {

TEST(InvariantCheck, AFailedCheckPrintsBothOperandsAndAborts) {
#ifdef TRIVOX_CHECKS
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const int four = 2 + 2;
  EXPECT_DEATH(TRIVOX_CHECK_EQ(four, 5), "internal check failed at .*check_test.cpp:[0-9]+: four == 5 with 4 and 5");
  EXPECT_DEATH(TRIVOX_CHECK(four < 0), "four < 0");
  TRIVOX_CHECK_LT(four, 5);  // holds: nothing happens
#else
  int evaluated = 0;
  TRIVOX_CHECK_EQ(++evaluated, 5);
  EXPECT_EQ(evaluated, 0) << "checks compiled out must not evaluate their operands";
  GTEST_SKIP() << "invariant checks are compiled in the sanitizer and Debug builds only (TRIVOX_CHECKS)";
#endif
}

}  // namespace
}  // namespace trivox
