// Checks of numeric options that print numbers as a person reads them. CLI11's own range
// checks print their bounds with %f (the largest double as 309 digits) and echo the value
// whole; these print numbers in %g style with at most 17 significant digits and a long value
// cut (trivox::shown_name). A failed check is a usage error (exit 2), like CLI11's.
#pragma once

#include <CLI/CLI.hpp>

namespace trivox::cli {

// A finite number > 0.
CLI::Validator positive_number();
// A finite number in [lo, hi].
CLI::Validator number_in(double lo, double hi);
// A worker-thread count: 0 (every core) to max_worker_count() (4 per hardware thread).
CLI::Validator thread_count();

}  // namespace trivox::cli
