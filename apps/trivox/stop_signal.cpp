#include "stop_signal.h"

#include <signal.h>

#include <string>

#include "trivox/error.h"

namespace trivox::cli {

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void on_stop_signal(int) { g_stop.store(true); }

}  // namespace

const std::atomic<bool>* stop_on_signals() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return true;
  }();
  (void)installed;
  return &g_stop;
}

void throw_if_signalled(const char* during) {
  if (g_stop.load()) throw CancelledError(std::string("stopped by a signal while ") + during);
}

}  // namespace trivox::cli
