#include "probe_input.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include <fmt/format.h>

namespace trivox::cli {

namespace {

bool is_separator(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == ','; }

// Shortens a token quoted in a message, so a long garbage line gives a readable error.
std::string quoted(std::string_view token) {
  constexpr std::size_t kMax = 40;
  return token.size() <= kMax ? fmt::format("'{}'", token) : fmt::format("'{}...'", token.substr(0, kMax));
}

}  // namespace

ProbeLine parse_probe_line(std::string_view line, std::size_t expected, std::string_view names) {
  ProbeLine out;
  if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);

  std::vector<std::string_view> tokens;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && is_separator(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !is_separator(line[pos])) ++pos;
    if (pos > start) tokens.push_back(line.substr(start, pos - start));
  }
  if (tokens.empty()) return out;
  out.has_data = true;

  for (std::string_view token : tokens) {
    // std::from_chars reads the C locale's format but, unlike strtod, rejects a leading '+'.
    std::string_view digits = token;
    if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
    double value = 0.0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || end != digits.data() + digits.size()) {
      out.error = ec == std::errc::result_out_of_range
                      ? fmt::format("{} is out of the range of a double", quoted(token))
                      : fmt::format("{} is not a number", quoted(token));
      out.values.clear();
      return out;
    }
    if (!std::isfinite(value)) {
      out.error = fmt::format("{} is not a finite number", quoted(token));
      out.values.clear();
      return out;
    }
    out.values.push_back(value);
  }
  if (out.values.size() != expected) {
    out.error = fmt::format("expected {} number{} ({}), found {}", expected, expected == 1 ? "" : "s", names,
                            out.values.size());
    out.values.clear();
  }
  return out;
}

}  // namespace trivox::cli
