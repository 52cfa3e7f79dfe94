// Stopping long work: a stop flag (std::atomic<bool>, may be set from a signal handler, a
// progress callback or another thread) that the library reads at the points its long steps
// name, throwing CancelledError (error.h) once it is raised.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "trivox/error.h"

namespace trivox {

// Throws CancelledError("stopped while <during>") once `stop` is raised; nothing when it is
// null or lowered. One relaxed load: cheap enough for once per row.
inline void throw_if_stopped(const std::atomic<bool>* stop, const char* during) {
  if (stop != nullptr && stop->load(std::memory_order_relaxed))
    throw CancelledError(std::string("stopped while ") + during);
}

// A stop flag read at the first step and then once every 65536: for loops whose single step (a
// token of a model file, a pair of triangles) is too cheap for a load each time, yet whose
// whole may run for seconds. A raised flag is seen within 65536 steps.
class StopPoll {
 public:
  StopPoll(const std::atomic<bool>* stop, const char* during) noexcept : stop_(stop), during_(during) {}
  void step() {
    if (stop_ != nullptr && (steps_++ & 0xFFFFu) == 0) throw_if_stopped(stop_, during_);
  }

 private:
  const std::atomic<bool>* stop_;
  const char* during_;
  std::uint32_t steps_ = 0;
};

}  // namespace trivox
