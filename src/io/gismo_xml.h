// Shared pieces of the G+Smo XML reader: turning pugixml's byte offsets into line numbers,
// naming an element for error messages, and reading an element's numbers (ASCII, with
// fractions like 1/3, or base64 binary in one of G+Smo's B64 formats).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <pugixml.hpp>

#include "trivox/cancel.h"

namespace trivox::io_detail {

class XmlContext {
 public:
  // `stop` (may be null) is read every 65536 numbers read_values() reads.
  XmlContext(std::string_view text, const std::string& source, const std::atomic<bool>* stop = nullptr);

  const std::string& source() const noexcept { return source_; }
  // 1-based line of a byte offset into the text (0 for a negative offset: unknown).
  int line_at(std::ptrdiff_t offset) const noexcept;
  int line_of(pugi::xml_node node) const noexcept { return line_at(node.offset_debug()); }

  // "Geometry TensorNurbs3 id=100 > Basis TensorNurbsBasis3 > weights": the element and its
  // ancestors below the root, with their type and id attributes and, among same-named
  // siblings, their position (#k, counted from 0) so the reader can find it.
  std::string where(pugi::xml_node node) const;

  // InputError at the element's line.
  [[noreturn]] void fail(pugi::xml_node node, std::string rule) const;
  // InputError at a given line (a number inside a long text block), naming the element.
  [[noreturn]] void fail_at(int line, pugi::xml_node node, std::string rule) const;
  // UnsupportedError at the element's line.
  [[noreturn]] void unsupported(pugi::xml_node node, std::string rule) const;

  // The numbers an element holds, by its format attribute: absent or "ASCII" for blank-
  // separated decimal numbers or fractions ("1/3"); "B64Float64", "B64Float32", "B64Int32",
  // ... (case-insensitive) for base64 little-endian binary values. Every value must be finite.
  std::vector<double> read_values(pugi::xml_node node) const;

 private:
  std::vector<double> read_ascii(pugi::xml_node node) const;
  std::vector<double> read_base64(pugi::xml_node node, const std::string& format) const;

  const std::string& source_;
  std::vector<std::size_t> line_starts_;  // byte offset where each line begins
  mutable StopPoll stop_;
};

// The element's only child named `name`: InputError when there is none or more than one.
pugi::xml_node only_child(const XmlContext& ctx, pugi::xml_node parent, const char* name);

}  // namespace trivox::io_detail
