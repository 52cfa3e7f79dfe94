// Stopping long work: a stop flag (std::atomic<bool>, may be set from a signal handler, a
// progress callback or another thread) that the library reads at the points its long steps
// name, throwing CancelledError (error.h) once it is raised.
#pragma once

#include <atomic>
#include <string>

#include "trivox/error.h"

namespace trivox {

// Throws CancelledError("stopped while <during>") once `stop` is raised; nothing when it is
// null or lowered. One relaxed load: cheap enough for once per row.
inline void throw_if_stopped(const std::atomic<bool>* stop, const char* during) {
  if (stop != nullptr && stop->load(std::memory_order_relaxed))
    throw CancelledError(std::string("stopped while ") + during);
}

}  // namespace trivox
