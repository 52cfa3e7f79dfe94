#include "check.h"

#include <cstdio>
#include <cstdlib>

namespace trivox::detail {

void check_failed(const char* file, int line, const char* expression, const std::string& operands) {
  std::fprintf(stderr, "trivox: internal check failed at %s:%d: %s %s\n", file, line, expression, operands.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace trivox::detail
