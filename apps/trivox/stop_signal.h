// SIGINT and SIGTERM for the commands that run long (slice, validate, build, merge, verify,
// probe, info): a scheduler sends SIGTERM at a time limit or a preemption, then kills; a person
// presses Ctrl-C. The first signal raises one flag the command hands to the library as its
// stop flag (JobParams::stop, SliceParams::stop, read_scene's), so the command ends cleanly
// within a second: a job's manifest says interrupted and the job can be resumed; a command
// stopped before it wrote anything throws CancelledError (exit 130, "nothing was written").
// The handler is reset by the first signal, so a second one ends the program at once.
#pragma once

#include <atomic>

namespace trivox::cli {

// Installs the handlers (once; later calls return the same flag) and returns the flag.
const std::atomic<bool>* stop_on_signals();

// Throws trivox::CancelledError, naming `during`, when a signal has raised the flag.
void throw_if_signalled(const char* during);

}  // namespace trivox::cli
