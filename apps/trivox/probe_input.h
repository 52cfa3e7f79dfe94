// Lines of `trivox probe`'s input: a fixed count of numbers per line, separated by blanks or
// commas; '#' starts a comment that runs to the end of the line; lines with nothing but
// blanks and comments carry no data.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::cli {

struct ProbeLine {
  bool has_data = false;       // false for a blank or comment-only line
  std::vector<double> values;  // the numbers, when the line is well formed
  std::string error;           // why the line is malformed; empty when it is not
};

// Parses one input line expecting `expected` finite numbers; `names` lists them for messages
// ("x y z"). Numbers use the C locale's decimal point and may have a leading '+'.
ProbeLine parse_probe_line(std::string_view line, std::size_t expected, std::string_view names);

}  // namespace trivox::cli
