// Base64 (RFC 4648, standard alphabet, '=' padding) decoding for the binary number arrays
// of G+Smo XML files (format="B64Float64" and friends).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::io_detail {

// Decodes `text`, ignoring blanks anywhere in it (XML text is often wrapped). Returns false
// and sets `error` to the rule broken (a character outside the alphabet, a length that is
// not a multiple of 4 characters, padding before the end).
bool decode_base64(std::string_view text, std::vector<std::uint8_t>& out, std::string& error);

}  // namespace trivox::io_detail
