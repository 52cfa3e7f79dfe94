// Strict parsing of one number token, shared by the IRIT and G+Smo readers: the whole token
// must be the number (no trailing garbage, no locale), so "1.5x" or "--2" are rejected
// instead of silently read as 1.5 or 0 the way sscanf/atof would.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "trivox/limits.h"
#include "trivox/spline/tensor_spline.h"

namespace trivox::io_detail {

// A decimal floating-point token ("-1.5e-3", "+2", "7."). "inf" and "nan" parse (to the
// non-finite values) so the caller can name that rule precisely; a literal too large for a
// double comes back as infinity for the same reason. nullopt when the token is not a number.
inline std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects '+'; sscanf and IRIT accept it
  if (s.empty() || s.front() == '+') return std::nullopt;
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (end != s.data() + s.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // Overflow (|v| huge) reads as infinity; underflow (tiny) as zero, which is harmless.
    const bool tiny = s.find_first_of("eE") != std::string_view::npos && s[s.find_first_of("eE") + 1] == '-';
    const bool negative = s.front() == '-';
    if (tiny) return negative ? -0.0 : 0.0;
    return negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  }
  if (ec != std::errc{}) return std::nullopt;
  return v;
}

// A decimal integer token ("12", "+3", "-1"). nullopt when the token is not an integer or
// does not fit in 64 bits.
inline std::optional<std::int64_t> parse_integer(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty() || s.front() == '+') return std::nullopt;
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return v;
}

// Why `v`, read as the text `text` from a model file, cannot be one of a model's numbers: not
// finite, or beyond kMaxModelNumber (trivox/limits.h), where a volume's derivatives and det J
// overflow; nullopt when it can. The one wording of these refusals for every model reader.
inline std::optional<std::string> model_number_problem(double v, std::string_view text) {
  if (!std::isfinite(v)) return fmt::format("'{}' is not finite (NaN and infinity are not allowed)", text);
  if (std::abs(v) > kMaxModelNumber)
    return fmt::format(
        "'{}' overflows: numbers beyond {:g} overflow the volume's derivatives and det J, and lose all precision "
        "beside the rest of the model",
        text, kMaxModelNumber);
  return std::nullopt;
}

// Why the rational spline `s`, read from a model file, could not be written back to one that
// reads again: its coordinates x (G+Smo files hold them) and weighted coordinates w * x (IRIT and
// GoTools files hold them) must be numbers a model file may hold (kMaxModelNumber). The readers
// divide w * x by w and the writers multiply back, which may round just past the limit: the
// weighted coordinates keep a margin of a hundred-trillionth below it, room for that and for
// the few ulps by which the .g2 writer moves a product so that it divides back exactly.
// nullopt for a polynomial spline, whose numbers are the file's own.
inline std::optional<std::string> rational_numbers_problem(const TensorSpline& s) {
  constexpr double kWeightedLimit = kMaxModelNumber * (1.0 - 1e-14);
  const auto dim = static_cast<std::size_t>(s.point_dim());
  for (std::size_t i = 0; i < s.weights().size(); ++i)
    for (std::size_t c = 0; c < dim; ++c) {
      const double x = s.points()[i * dim + c], w = s.weights()[i];
      if (!(std::abs(w * x) <= kWeightedLimit) || !(std::abs(x) <= kMaxModelNumber))
        return fmt::format(
            "control point {}: weight {} times coordinate {} is {}, which overflows: a rational spline's "
            "coordinates and weighted coordinates are numbers of at most {:g} in magnitude, as in a model file",
            i, w, x, w * x, kMaxModelNumber);
    }
  return std::nullopt;
}

}  // namespace trivox::io_detail
