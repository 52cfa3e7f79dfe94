// The IRIT .itd parser's state and steps, shared by the files that read its parts: the
// object structure (itd_reader.cpp), the MODEL topology (itd_model_reader.cpp) and the
// spline bodies (itd_spline_reader.cpp). See itd_reader.cpp for the format.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/itd_tokenizer.h"
#include "io/text_number.h"
#include "trivox/error.h"
#include "trivox/io/model.h"

namespace trivox::itd {

// Limits that turn corrupt or hostile headers into errors before anything is allocated.
constexpr int kMaxNesting = 1000;  // objects (and models) inside objects
constexpr const char* kDirection[3] = {"u", "v", "w"};
constexpr const char* kKeyword[4] = {"", "CURVE", "SURFACE", "TRIVAR"};

struct PointType {
  int dim = 3;
  bool rational = false;
  std::string_view name;
};

class ItdParser {
 public:
  ItdParser(std::string_view text, const std::string& source, const std::atomic<bool>* stop)
      : text_(text), tok_(text, source, stop), source_(source) {}

  Model parse();

 private:
  [[noreturn]] void fail(int line, const std::string& where, std::string rule) const {
    throw InputError(source_, line, where, std::move(rule));
  }
  // The line to report for a token: where the file stops when the token is its end.
  int line_of(const Token& t) const noexcept { return t.is_end() ? tok_.last_line() : t.line; }
  [[noreturn]] void fail_eof(const std::string& where, const Token& open) const {
    fail(tok_.last_line(), where,
         fmt::format("unexpected end of file: the '[' opened at line {} is never closed", open.line));
  }

  void parse_item(const Token& open, int depth);
  void parse_object(const Token& open, int depth);
  void parse_trimmed(const Token& open, int depth);
  // Kept out of parse_item, which recurses once per nested object: inlined there, a MODEL's
  // locals would grow every level's stack frame (AddressSanitizer's frames overflowed the
  // stack before the nesting limit).
  [[gnu::noinline]] void parse_model(const Token& open);
  void parse_model_surface(const Token& open, TrimmedModel& model, const std::string& where);
  void parse_model_segment(const Token& open, TrimmedModel& model, const std::string& where);
  void skip_group(const Token& open);
  // The next '[' in the body of the group `open` opened, or nothing at its ']'; fails at the
  // end of the file or on anything else ("unexpected <token><in>: expected '[' or ']'").
  std::optional<Token> next_group(const Token& open, const std::string& where, std::string_view in);
  void read_geometry(const Token& keyword, int param_dim);
  KnotVector read_knots(const std::string& where, int dir, int num_ctrl, int order);
  void read_point(const std::string& where, std::int64_t index, std::int64_t total, const PointType& pt,
                  std::vector<double>& points, std::vector<double>& weights);
  double read_number(const Token& t, const std::string& where, const char* what) const;
  int read_int(const std::string& where, const std::string& what, std::int64_t lo, std::int64_t hi);
  std::string object_name() const;

  std::string_view text_;
  Tokenizer tok_;
  const std::string& source_;
  std::vector<std::string> names_;  // names of the enclosing objects, outermost first
  std::vector<Patch> patches_;
  std::vector<TrimmedModel> models_;
};

inline bool is_number(const Token& t) { return t.is_word() && io_detail::parse_double(t.text).has_value(); }

}  // namespace trivox::itd
