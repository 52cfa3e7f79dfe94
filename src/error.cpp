#include "trivox/error.h"

#include <fmt/format.h>

namespace trivox {

namespace {
std::string format_input_error(const std::string& file, int line, const std::string& where, const std::string& rule) {
  std::string location = line > 0 ? fmt::format("{}:{}", file, line) : file;
  return where.empty() ? fmt::format("{}: {}", location, rule) : fmt::format("{}: {}: {}", location, where, rule);
}
}  // namespace

InputError::InputError(std::string file, int line, std::string where, std::string rule)
    : Error(format_input_error(file, line, where, rule)),
      file_(std::move(file)),
      line_(line),
      where_(std::move(where)),
      rule_(std::move(rule)) {}

}  // namespace trivox
