#include "cli_checks.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "trivox/error.h"
#include "trivox/parallel.h"

namespace trivox::cli {

namespace {

// The whole text as a finite double; nullopt for anything else (CLI11 then reports it).
std::optional<double> finite_number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(x)) return std::nullopt;
  return x;
}

// %g with up to 17 significant digits: 86400, 1e-06, 1.7976931348623157e+308.
std::string number_text(double x) { return fmt::format("{:.17g}", x); }

}  // namespace

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const auto x = finite_number(text);
        if (x && *x > 0) return {};
        return fmt::format("Value {} is not a finite number > 0", shown_name(text));
      },
      "POSITIVE");
}

CLI::Validator number_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const auto x = finite_number(text);
        if (x && *x >= lo && *x <= hi) return {};
        return fmt::format("Value {} is not a number from {} to {}", shown_name(text), number_text(lo),
                           number_text(hi));
      },
      fmt::format("[{} - {}]", number_text(lo), number_text(hi)));
}

CLI::Validator thread_count() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const auto x = finite_number(text);
        if (x && *x >= 0 && *x <= max_worker_count() && *x == std::floor(*x)) return {};
        return fmt::format("Value {} is no thread count: 0 (every core) to {} (4 per hardware thread of this machine)",
                           shown_name(text), max_worker_count());
      },
      "THREADS");
}

}  // namespace trivox::cli
