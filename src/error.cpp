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

std::string shown_name(std::string_view name, char quote) {
  constexpr std::size_t kShownBytes = 80;
  const auto is_continuation = [](char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; };
  std::size_t shown = name.size();
  if (shown > kShownBytes) {
    shown = kShownBytes;
    while (shown > 0 && is_continuation(name[shown])) --shown;
  }
  std::string out(1, quote);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (c < 0x20 || c == 0x7f)  // the set first_control_character finds
      out += fmt::format("\\x{:02X}", c);
    else
      out += name[i];
  }
  out += quote;
  if (shown < name.size()) {
    std::size_t characters = 0;
    for (char c : name) characters += is_continuation(c) ? 0 : 1;
    out += fmt::format("... ({} characters)", characters);
  }
  return out;
}

std::optional<unsigned char> first_control_character(std::string_view text) {
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) return u;
  }
  return std::nullopt;
}

}  // namespace trivox
