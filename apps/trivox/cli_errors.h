// The program's exit codes (documented in docs/CLI.md) and the one error type that belongs to
// the program rather than the library.
#pragma once

#include <stdexcept>

namespace trivox::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,       // a bug or an unexpected failure (out of memory, an unknown exception)
  kExitUsage = 2,          // the command line is malformed or asks for something the model lacks
  kExitInput = 3,          // the input breaks a rule: a model, scene, setting or input line
                           // (trivox::InputError, UnsupportedError, ModelError, other trivox::Error)
  kExitIo = 4,             // a file cannot be read or written (trivox::IoError, system errors)
  kExitCorrupt = 5,        // `trivox verify` found a missing, changed or undecodable file
  kExitEmpty = 6,          // `trivox slice` made, or would make, a stack without the object
  kExitInterrupted = 130,  // SIGINT / SIGTERM stopped a job cleanly; it can be resumed
};

// A command line that parses but cannot be carried out on the model it names, e.g.
// `--patch 7` for a model of two patches. Mapped to kExitUsage like a CLI11 parse error.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A job stopped by a signal after recording its state (mapped to kExitInterrupted).
class InterruptedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `trivox verify` found problems, already listed on standard output (mapped to kExitCorrupt).
class CorruptOutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace trivox::cli
