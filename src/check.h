// Invariant checks for bugs inside the library, in the style of pbrt's CHECK_EQ: a failed
// check prints the file, the line, the expression and both operands on standard error and
// aborts (a broken invariant is a bug, never bad input: input errors are exceptions, see
// trivox/error.h). The checks are compiled in where TRIVOX_CHECKS is defined, as it is in
// the sanitizer builds (CMake option TRIVOX_SANITIZE) and Debug builds; elsewhere they
// compile to nothing and their operands are not evaluated, so the release build's hot
// paths pay nothing for them.
#pragma once

#include <sstream>
#include <string>

namespace trivox::detail {

[[noreturn]] void check_failed(const char* file, int line, const char* expression, const std::string& operands);

template <typename A, typename B>
std::string check_operands(const A& a, const B& b) {
  std::ostringstream s;
  s << "with " << a << " and " << b;
  return s.str();
}

}  // namespace trivox::detail

#ifdef TRIVOX_CHECKS
#define TRIVOX_CHECK(cond) ((cond) ? (void)0 : ::trivox::detail::check_failed(__FILE__, __LINE__, #cond, std::string()))
#define TRIVOX_CHECK_OP(a, op, b)                                                                       \
  do {                                                                                                  \
    const auto& trivox_check_a = (a);                                                                   \
    const auto& trivox_check_b = (b);                                                                   \
    if (!(trivox_check_a op trivox_check_b))                                                            \
      ::trivox::detail::check_failed(__FILE__, __LINE__, #a " " #op " " #b,                             \
                                     ::trivox::detail::check_operands(trivox_check_a, trivox_check_b)); \
  } while (false)
#else
#define TRIVOX_CHECK(cond) ((void)0)
#define TRIVOX_CHECK_OP(a, op, b) \
  do {                            \
  } while (false)
#endif

#define TRIVOX_CHECK_EQ(a, b) TRIVOX_CHECK_OP(a, ==, b)
#define TRIVOX_CHECK_NE(a, b) TRIVOX_CHECK_OP(a, !=, b)
#define TRIVOX_CHECK_LT(a, b) TRIVOX_CHECK_OP(a, <, b)
#define TRIVOX_CHECK_LE(a, b) TRIVOX_CHECK_OP(a, <=, b)
#define TRIVOX_CHECK_GE(a, b) TRIVOX_CHECK_OP(a, >=, b)
