#include "io/itd_tokenizer.h"

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::itd {

namespace {
bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
char lower(char c) noexcept { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }
}  // namespace

bool Token::is_keyword(std::string_view keyword) const noexcept {
  if (kind != TokenKind::kWord || text.size() != keyword.size()) return false;
  for (std::size_t i = 0; i < text.size(); ++i)
    if (lower(text[i]) != lower(keyword[i])) return false;
  return true;
}

std::string describe(const Token& t) {
  switch (t.kind) {
    case TokenKind::kOpen: return "'['";
    case TokenKind::kClose: return "']'";
    case TokenKind::kEnd: return "end of file";
    case TokenKind::kString: return fmt::format("string \"{}\"", t.text.substr(0, 40));
    case TokenKind::kWord: break;
  }
  return fmt::format("'{}'", t.text.substr(0, 40));
}

Tokenizer::Tokenizer(std::string_view text, const std::string& source, const std::atomic<bool>* stop)
    : text_(text), source_(&source), stop_(stop, "reading a model") {}

void Tokenizer::skip_blanks() {
  while (pos_ < text_.size() && is_blank(text_[pos_])) {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
}

Token Tokenizer::next() {
  stop_.step();
  skip_blanks();
  Token t;
  t.line = line_;
  if (pos_ >= text_.size()) return t;  // kEnd
  last_line_ = line_;
  const char c = text_[pos_];
  if (c == '[' || c == ']') {
    t.kind = c == '[' ? TokenKind::kOpen : TokenKind::kClose;
    t.text = text_.substr(pos_, 1);
    ++pos_;
    return t;
  }
  if (c == '"') {
    // IRIT strings end at the closing quote; a backslash quotes the next character.
    const std::size_t start = ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '"') {
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) ++pos_;
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size())
      throw InputError(*source_, t.line, "", "string opened here is never closed (missing '\"')");
    t.kind = TokenKind::kString;
    t.text = text_.substr(start, pos_ - start);
    ++pos_;
    return t;
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size()) {
    const char d = text_[pos_];
    if (is_blank(d) || d == '[' || d == ']' || d == '"') break;
    // IRIT rejects control characters the same way: they mean a binary file, not text.
    if (static_cast<unsigned char>(d) < 0x20)
      throw InputError(*source_, line_, "",
                       fmt::format("control character 0x{:02x}: not an IRIT text file", static_cast<int>(d)));
    ++pos_;
  }
  t.kind = TokenKind::kWord;
  t.text = text_.substr(start, pos_ - start);
  return t;
}

Token Tokenizer::peek() const {
  Tokenizer copy = *this;
  return copy.next();
}

Token Tokenizer::peek2() const {
  Tokenizer copy = *this;
  copy.next();
  return copy.next();
}

}  // namespace trivox::itd
