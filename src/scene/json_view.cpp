#include "scene/json_view.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "trivox/error.h"

namespace trivox::detail {

namespace {

// RFC 6901: '~' is written "~0" and '/' "~1" inside a pointer's reference token.
std::string escape_token(std::string_view token) {
  std::string out;
  for (char c : token) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

std::string quoted_list(std::initializer_list<std::string_view> names) {
  std::string out;
  for (std::string_view n : names) {
    if (!out.empty()) out += ", ";
    out += fmt::format("\"{}\"", n);
  }
  return out;
}

}  // namespace

void JsonView::fail(const std::string& rule) const { throw InputError(*source_, 0, pointer_, rule); }

std::string JsonView::describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return fmt::format("the string {}", value.dump());
    case Json::value_t::boolean: return fmt::format("the boolean {}", value.dump());
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return fmt::format("the number {}", value.dump());
    default: return "a value of another kind";
  }
}

JsonView JsonView::child(std::string_view token, const Json& value) const {
  return JsonView(value, pointer_ + "/" + escape_token(token), *source_);
}

void JsonView::expect_object(std::initializer_list<std::string_view> allowed) const {
  if (!is_object()) fail(fmt::format("expected an object, got {}", describe(*value_)));
  for (const auto& [key, value] : value_->items()) {
    bool known = false;
    for (std::string_view a : allowed) known = known || key == a;
    if (!known)
      child(key, value)
          .fail(fmt::format("unknown key \"{}\"; the keys allowed here are {}", key, quoted_list(allowed)));
  }
}

JsonView JsonView::at(std::string_view key) const {
  std::optional<JsonView> v = find(key);
  if (!v) fail(fmt::format("the required key \"{}\" is missing", key));
  return *v;
}

std::optional<JsonView> JsonView::find(std::string_view key) const {
  if (!is_object()) fail(fmt::format("expected an object, got {}", describe(*value_)));
  const auto it = value_->find(std::string(key));
  if (it == value_->end()) return std::nullopt;
  return child(key, *it);
}

std::vector<std::pair<std::string, JsonView>> JsonView::members() const {
  if (!is_object()) fail(fmt::format("expected an object, got {}", describe(*value_)));
  std::vector<std::pair<std::string, JsonView>> out;
  for (const auto& [key, value] : value_->items()) out.emplace_back(key, child(key, value));
  return out;
}

std::vector<JsonView> JsonView::elements(std::size_t min_size, std::size_t max_size) const {
  if (!is_array()) fail(fmt::format("expected an array, got {}", describe(*value_)));
  const std::size_t n = value_->size();
  if (n < min_size || n > max_size) {
    if (min_size == max_size) fail(fmt::format("expected an array of {} elements, got {}", min_size, n));
    if (max_size == static_cast<std::size_t>(-1))
      fail(fmt::format("expected an array of at least {} element(s), got {}", min_size, n));
    fail(fmt::format("expected an array of {} to {} elements, got {}", min_size, max_size, n));
  }
  std::vector<JsonView> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(child(std::to_string(i), (*value_)[i]));
  return out;
}

double JsonView::number() const {
  if (!is_number()) fail(fmt::format("expected a number, got {}", describe(*value_)));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail(fmt::format("{} is not a finite number", value_->dump()));
  return v;
}

double JsonView::number_in(double lo, double hi) const {
  const double v = number();
  if (v < lo || v > hi) fail(fmt::format("{} is outside [{}, {}]", value_->dump(), lo, hi));
  return v;
}

int JsonView::integer() const {
  const double v = number();
  if (v != std::floor(v) || v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(fmt::format("expected an integer, got {}", value_->dump()));
  return static_cast<int>(v);
}

int JsonView::integer_in(int lo, int hi) const {
  const int v = integer();
  if (v < lo || v > hi) fail(fmt::format("{} is outside [{}, {}]", v, lo, hi));
  return v;
}

const std::string& JsonView::string() const {
  if (!is_string()) fail(fmt::format("expected a string, got {}", describe(*value_)));
  return value_->get_ref<const std::string&>();
}

const std::string& JsonView::name(std::string_view what) const {
  const std::string& text = string();
  if (text.empty()) fail(fmt::format("{} name must not be empty", what));
  if (const auto c = first_control_character(text))
    fail(fmt::format("{} name must hold no control character; {} holds 0x{:02X}", what, shown_name(text, '"'), *c));
  return text;
}

bool JsonView::boolean() const {
  if (!value_->is_boolean()) fail(fmt::format("expected true or false, got {}", describe(*value_)));
  return value_->get<bool>();
}

std::vector<double> JsonView::numbers(std::size_t min_size, std::size_t max_size) const {
  std::vector<double> out;
  for (const JsonView& e : elements(min_size, max_size)) out.push_back(e.number());
  return out;
}

}  // namespace trivox::detail
