// Tokens of IRIT's text format (.itd): '[' and ']' always stand alone, "quoted strings" are
// one token (they may hold brackets: `[dash "0 [0.1 0.1] 0"]`), every other run of
// non-blank characters is a word (keyword, name or number). Each token keeps the line it
// starts on so every error can say file:line. The tokenizer never allocates: tokens are views
// into the text, which must outlive them.
#pragma once

#include <string>
#include <string_view>

#include "trivox/cancel.h"

namespace trivox::itd {

enum class TokenKind { kOpen, kClose, kWord, kString, kEnd };

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string_view text;  // the word or the string's contents (without quotes)
  int line = 0;           // 1-based line where the token starts

  bool is_open() const noexcept { return kind == TokenKind::kOpen; }
  bool is_close() const noexcept { return kind == TokenKind::kClose; }
  bool is_word() const noexcept { return kind == TokenKind::kWord; }
  bool is_end() const noexcept { return kind == TokenKind::kEnd; }
  // Case-insensitive keyword test, as IRIT compares keywords with stricmp.
  bool is_keyword(std::string_view keyword) const noexcept;
};

// Human-readable form of a token for error messages: '[', ']', "end of file", 'WORD'.
std::string describe(const Token& t);

class Tokenizer {
 public:
  // `source` names the input in errors (InputError for control characters, which mean the
  // file is binary, and for a string left open at the end of the file). `stop` (may be null)
  // is read every 65536 tokens.
  Tokenizer(std::string_view text, const std::string& source, const std::atomic<bool>* stop = nullptr);

  Token next();
  // The token next() would return, and the one after it; the tokenizer's state is a position
  // and a line, so looking ahead is a copy.
  Token peek() const;
  Token peek2() const;

  // Line of the last token next() returned (0 before the first): where a file that ends too
  // early stops, for "unexpected end of file" errors.
  int last_line() const noexcept { return last_line_; }

 private:
  void skip_blanks();

  std::string_view text_;
  const std::string* source_;
  StopPoll stop_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int last_line_ = 0;
};

}  // namespace trivox::itd
