// Errors in layers (see docs/ARCHITECTURE.md):
//  * bugs (a broken invariant inside the library) are caught by the invariant checks of
//    src/check.h (TRIVOX_CHECK_EQ and its kin, which print both operands and abort), compiled
//    into the sanitizer and Debug builds;
//  * bad input (a model file, a scene, a parameter) throws a typed exception derived from
//    trivox::Error that names where the problem is and which rule it breaks;
//  * expected numerical outcomes (a point outside a volume, a Newton iteration that does not
//    converge) are status values, never exceptions.
// The library never prints and never exits (but for a failed invariant check, a bug); only
// the command-line program turns errors into messages and exit codes.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace trivox {

// Base of every exception the library throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A spline or model that breaks a structural rule (knots decreasing, weight <= 0, NaN...).
// Thrown by constructors that validate; readers catch it and add the file and line.
class ModelError : public Error {
 public:
  using Error::Error;
};

// Bad input read from a file: names the file, the line (0 when unknown) or XML element,
// and the rule broken. what() is "file:line: where: rule".
class InputError : public Error {
 public:
  InputError(std::string file, int line, std::string where, std::string rule);

  const std::string& file() const noexcept { return file_; }
  int line() const noexcept { return line_; }
  const std::string& where() const noexcept { return where_; }
  const std::string& rule() const noexcept { return rule_; }

 private:
  std::string file_;
  int line_;
  std::string where_;
  std::string rule_;
};

// A feature of a valid file that trivox does not handle (e.g. hierarchical splines).
class UnsupportedError : public InputError {
 public:
  using InputError::InputError;
};

// A file or folder that cannot be read or written.
class IoError : public Error {
 public:
  using Error::Error;
};

// A long computation saw its caller's stop flag raised (a `stop` member of its parameters,
// set from a signal handler, a progress callback or another thread) and gave up, leaving
// nothing half-written. Not a problem with the input: the same call without the stop
// succeeds.
class CancelledError : public Error {
 public:
  using Error::Error;
};

// A job that sliced every layer of the object itself made a stack without a voxel of it (no
// pixel centre lies inside a cell: the object is thinner than a pixel, or falls between pixel
// centres), or would (its bitmap is under 2 pixels along x or y). The files are complete; the
// caller asked for the object and did not get it (SliceJobParams::allow_empty accepts it).
class EmptyResultError : public Error {
 public:
  using Error::Error;
};

// A name from the input (a material, a cell, a prefix) as messages show it, in `quote`s: control
// characters as \xNN, and a name longer than 80 bytes cut after them (at a UTF-8 character's
// start) with its length: 'aaaa...' (1000000 characters). Messages stay one readable line
// whatever the input holds.
std::string shown_name(std::string_view name, char quote = '\'');

// The first control character (below 0x20, or 0x7F) of `text`, or nullopt: names that go into
// files and manifests hold none (one rule for output file names and manifest entries).
std::optional<unsigned char> first_control_character(std::string_view text);

}  // namespace trivox
