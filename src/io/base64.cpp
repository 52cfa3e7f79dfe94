#include "io/base64.h"

#include <fmt/format.h>

namespace trivox::io_detail {

namespace {
// 0..63 for an alphabet character, -1 otherwise.
int sextet(char c) noexcept {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}
bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
}  // namespace

bool decode_base64(std::string_view text, std::vector<std::uint8_t>& out, std::string& error) {
  out.clear();
  out.reserve(text.size() / 4 * 3);
  std::uint32_t group = 0;  // up to four sextets
  int have = 0;             // sextets in `group`
  int padding = 0;          // '=' seen
  std::size_t chars = 0;    // non-blank characters
  for (char c : text) {
    if (is_blank(c)) continue;
    ++chars;
    if (c == '=') {
      ++padding;
      if (padding > 2 || have < 2) {
        error = "base64 padding '=' in the wrong place";
        return false;
      }
      continue;
    }
    const int v = sextet(c);
    if (v < 0) {
      error = fmt::format("character '{}' is not base64", c);
      return false;
    }
    if (padding > 0) {
      error = "base64 data continues after '=' padding";
      return false;
    }
    group = (group << 6) | static_cast<std::uint32_t>(v);
    if (++have == 4) {
      out.push_back(static_cast<std::uint8_t>(group >> 16));
      out.push_back(static_cast<std::uint8_t>(group >> 8));
      out.push_back(static_cast<std::uint8_t>(group));
      group = 0;
      have = 0;
    }
  }
  if (chars % 4 != 0) {
    error = fmt::format("base64 text of {} characters; a multiple of 4 is needed", chars);
    return false;
  }
  // A final group of 2 or 3 sextets (with 2 or 1 '=') carries 1 or 2 bytes.
  if (have == 2) out.push_back(static_cast<std::uint8_t>(group >> 4));
  if (have == 3) {
    out.push_back(static_cast<std::uint8_t>(group >> 10));
    out.push_back(static_cast<std::uint8_t>(group >> 2));
  }
  return true;
}

}  // namespace trivox::io_detail
