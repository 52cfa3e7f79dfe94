// JSON text for the line-oriented outputs (probe). Numbers carry 17 significant digits, so
// reading one back gives the identical double: the output is exact, and the same on every
// machine for the same double.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace trivox::cli {

// `x` with 17 significant digits ("0.10000000000000001", "60", "-2.5e-09"); `null` when x is
// not finite, since JSON has no NaN or infinity.
std::string json_number(double x);

// [a,b,c] with json_number for each element.
std::string json_numbers(std::span<const double> xs);

// A quoted, escaped JSON string; bytes that are not valid UTF-8 become U+FFFD.
std::string json_string(std::string_view s);

}  // namespace trivox::cli
