// JsonView: read-only access to one value of a parsed scene that knows its JSON pointer, so
// that every rule the reader checks fails with InputError(scene file, 0, pointer, rule).
// Keeps the typed checks (finite number, integer, string, object with known keys) in one
// place instead of scattering nlohmann's exceptions through the reader.
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace trivox::detail {

// Keeps keys in document order, so the first problem reported is the first in the file.
using Json = nlohmann::ordered_json;

class JsonView {
 public:
  JsonView(const Json& value, std::string pointer, const std::string& source)
      : value_(&value), pointer_(std::move(pointer)), source_(&source) {}

  const Json& json() const noexcept { return *value_; }
  const std::string& pointer() const noexcept { return pointer_; }
  const std::string& source() const noexcept { return *source_; }

  // Throws InputError(source, 0, pointer, rule).
  [[noreturn]] void fail(const std::string& rule) const;

  bool is_object() const noexcept { return value_->is_object(); }
  bool is_array() const noexcept { return value_->is_array(); }
  bool is_string() const noexcept { return value_->is_string(); }
  bool is_number() const noexcept { return value_->is_number(); }

  // Fails unless this is an object whose keys are all in `allowed` (catches typos).
  void expect_object(std::initializer_list<std::string_view> allowed) const;
  // Member `key` (must exist), or nullopt (find) when absent. Requires an object.
  JsonView at(std::string_view key) const;
  std::optional<JsonView> find(std::string_view key) const;
  // All members of an object, in document order, with their keys.
  std::vector<std::pair<std::string, JsonView>> members() const;

  // Elements of an array; fails when this is not an array or its size is outside
  // [min_size, max_size].
  std::vector<JsonView> elements(std::size_t min_size = 0, std::size_t max_size = static_cast<std::size_t>(-1)) const;

  double number() const;                         // a finite number
  double number_in(double lo, double hi) const;  // a finite number in [lo, hi]
  int integer() const;                           // an integral number that fits an int
  int integer_in(int lo, int hi) const;          // an integer in [lo, hi]
  const std::string& string() const;
  // A name the scene gives (a cell, a material, a union, a region): a string, not empty, without
  // control characters (names go into messages, manifests and file names); `what` names the
  // kind in the refusal ("a cell name must not be empty").
  const std::string& name(std::string_view what) const;
  bool boolean() const;
  std::vector<double> numbers(std::size_t min_size = 0, std::size_t max_size = static_cast<std::size_t>(-1)) const;

  // A JSON value's kind in words ("an object", "the number 3", ...), for messages.
  static std::string describe(const Json& value);

 private:
  JsonView child(std::string_view token, const Json& value) const;

  const Json* value_;
  std::string pointer_;
  const std::string* source_;
};

}  // namespace trivox::detail
