#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>

#include <fmt/format.h>

#include "io/base64.h"
#include "io/gismo_xml.h"
#include "io/text_number.h"
#include "trivox/error.h"
#include "trivox/limits.h"

namespace trivox::io_detail {

namespace {

std::string lowercase(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  return out;
}

bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// G+Smo's binary formats (gsIO/gsBase64.h): raw little-endian values of one type each.
enum class Binary { kF32, kF64, kI16, kI32, kI64, kU16, kU32, kU64 };
struct BinaryFormat {
  const char* name;  // lowercase format attribute
  Binary type;
  std::size_t bytes;
};
constexpr BinaryFormat kBinaryFormats[] = {
    {"b64float32", Binary::kF32, 4}, {"b64float64", Binary::kF64, 8}, {"b64int16", Binary::kI16, 2},
    {"b64int32", Binary::kI32, 4},   {"b64int64", Binary::kI64, 8},   {"b64uint16", Binary::kU16, 2},
    {"b64uint32", Binary::kU32, 4},  {"b64uint64", Binary::kU64, 8},
};

// Assembling the value byte by byte makes the result independent of the host's endianness.
double decode_value(const std::uint8_t* p, const BinaryFormat& f) {
  std::uint64_t bits = 0;
  for (std::size_t b = 0; b < f.bytes; ++b) bits |= static_cast<std::uint64_t>(p[b]) << (8 * b);
  switch (f.type) {
    case Binary::kF32: return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
    case Binary::kF64: return std::bit_cast<double>(bits);
    case Binary::kI16: return static_cast<double>(static_cast<std::int16_t>(static_cast<std::uint16_t>(bits)));
    case Binary::kI32: return static_cast<double>(static_cast<std::int32_t>(static_cast<std::uint32_t>(bits)));
    case Binary::kI64: return static_cast<double>(static_cast<std::int64_t>(bits));
    case Binary::kU16:
    case Binary::kU32:
    case Binary::kU64: return static_cast<double>(bits);
  }
  return 0.0;
}

}  // namespace

XmlContext::XmlContext(std::string_view text, const std::string& source, const std::atomic<bool>* stop)
    : source_(source), stop_(stop, "reading a model") {
  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_starts_.push_back(i + 1);
}

int XmlContext::line_at(std::ptrdiff_t offset) const noexcept {
  if (offset < 0) return 0;
  const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), static_cast<std::size_t>(offset));
  return static_cast<int>(it - line_starts_.begin());
}

std::string XmlContext::where(pugi::xml_node node) const {
  std::vector<std::string> parts;
  for (pugi::xml_node n = node; n && n.parent() && n.parent().type() != pugi::node_document; n = n.parent()) {
    std::string part = n.name();
    if (const auto type = n.attribute("type")) part += fmt::format(" {}", type.value());
    if (const auto id = n.attribute("id")) part += fmt::format(" id={}", id.value());
    int position = 0, count = 0;
    for (pugi::xml_node s = n.parent().child(n.name()); s; s = s.next_sibling(n.name())) {
      if (s == n) position = count;
      ++count;
    }
    if (count > 1) part += fmt::format(" #{}", position);
    parts.push_back(std::move(part));
  }
  std::string out;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) out += (out.empty() ? "" : " > ") + *it;
  return out.empty() ? std::string(node.name()) : out;
}

void XmlContext::fail(pugi::xml_node node, std::string rule) const {
  throw InputError(source_, line_of(node), where(node), std::move(rule));
}

void XmlContext::fail_at(int line, pugi::xml_node node, std::string rule) const {
  throw InputError(source_, line, where(node), std::move(rule));
}

void XmlContext::unsupported(pugi::xml_node node, std::string rule) const {
  throw UnsupportedError(source_, line_of(node), where(node), std::move(rule));
}

std::vector<double> XmlContext::read_values(pugi::xml_node node) const {
  const std::string format = lowercase(node.attribute("format").value());
  if (format.empty() || format == "ascii") return read_ascii(node);
  return read_base64(node, format);
}

std::vector<double> XmlContext::read_ascii(pugi::xml_node node) const {
  std::vector<double> values;
  for (pugi::xml_node text = node.first_child(); text; text = text.next_sibling()) {
    if (text.type() != pugi::node_pcdata && text.type() != pugi::node_cdata) continue;
    const std::string_view s = text.value();
    int line = line_of(text);  // follows the newlines so an error names the number's own line
    for (std::size_t i = 0; i < s.size();) {
      if (is_blank(s[i])) {
        if (s[i] == '\n') ++line;
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < s.size() && !is_blank(s[j])) ++j;
      const std::string_view token = s.substr(i, j - i);
      i = j;
      stop_.step();
      std::optional<double> v;
      if (const std::size_t slash = token.find('/'); slash != std::string_view::npos) {
        // G+Smo writes exact rationals as fractions: "1/3".
        const auto num = parse_double(token.substr(0, slash));
        const auto den = parse_double(token.substr(slash + 1));
        if (num && den && *den == 0.0) fail_at(line, node, fmt::format("fraction '{}' has a zero denominator", token));
        if (num && den) v = *num / *den;
      } else {
        v = parse_double(token);
      }
      if (!v) fail_at(line, node, fmt::format("'{}' is not a number", token.substr(0, 40)));
      if (const auto problem = model_number_problem(*v, token)) fail_at(line, node, *problem);
      values.push_back(*v);
    }
  }
  return values;
}

std::vector<double> XmlContext::read_base64(pugi::xml_node node, const std::string& format) const {
  const BinaryFormat* f = nullptr;
  for (const BinaryFormat& candidate : kBinaryFormats)
    if (format == candidate.name) f = &candidate;
  if (f == nullptr)
    fail(node, fmt::format("unknown number format '{}' (expected ASCII, B64Float32, B64Float64, B64Int16/32/64 "
                           "or B64UInt16/32/64)",
                           node.attribute("format").value()));
  std::string text;
  for (pugi::xml_node t = node.first_child(); t; t = t.next_sibling())
    if (t.type() == pugi::node_pcdata || t.type() == pugi::node_cdata) text += t.value();
  std::vector<std::uint8_t> bytes;
  std::string error;
  if (!decode_base64(text, bytes, error)) fail(node, fmt::format("invalid base64 data: {}", error));
  if (bytes.size() % f->bytes != 0)
    fail(node, fmt::format("base64 data of {} bytes is not a whole number of {}-byte values ({})", bytes.size(),
                           f->bytes, node.attribute("format").value()));
  std::vector<double> values;
  values.reserve(bytes.size() / f->bytes);
  for (std::size_t i = 0; i < bytes.size(); i += f->bytes) {
    stop_.step();
    const double v = decode_value(bytes.data() + i, *f);
    if (!std::isfinite(v))
      fail(node, fmt::format("base64 value {} is not finite (NaN and infinity are not allowed)", i / f->bytes));
    if (std::abs(v) > kMaxModelNumber)
      fail(node, fmt::format("base64 value {} is {:g}: numbers beyond {:g} overflow in a volume's det J", i / f->bytes,
                             v, kMaxModelNumber));
    values.push_back(v);
  }
  return values;
}

pugi::xml_node only_child(const XmlContext& ctx, pugi::xml_node parent, const char* name) {
  const pugi::xml_node first = parent.child(name);
  if (!first) ctx.fail(parent, fmt::format("<{}> has no <{}> child", parent.name(), name));
  if (const pugi::xml_node second = first.next_sibling(name))
    ctx.fail(second, fmt::format("<{}> holds more than one <{}>", parent.name(), name));
  return first;
}

}  // namespace trivox::io_detail
