// Tells ThreadSanitizer about the ordering oneTBB guarantees but TSan cannot see (used by
// the parallel seam, parallel.cpp, only).
//
// Debian's libtbb is not built with TSan, so the hand-off of a task to a worker and the
// return of parallel_for after its last task happen inside uninstrumented code: TSan would
// report every read a worker makes of data the caller wrote before parallel_for (and every
// read after it of what the workers wrote) as a race. The seam marks the two hand-offs with
// TsanHandoff: the caller publishes before starting the tasks, each task receives at its
// start and publishes at its end, the caller receives after they all finished. Tasks never
// receive each other's publications, so a true race between two layers is still reported.
// Outside a TSan build every call compiles to nothing.
#pragma once

#if defined(__SANITIZE_THREAD__)
#define TRIVOX_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define TRIVOX_TSAN 1
#endif
#endif

#ifdef TRIVOX_TSAN
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace trivox::detail {

// The tokens are globals rather than members of the job: a task must receive before it
// reads anything the caller wrote, and that includes the lambda's captured references.
// (Jobs running at the same time in one process share them, which can only hide a race
// between two jobs, never invent one.)
struct TsanHandoff {
#ifdef TRIVOX_TSAN
  static void caller_publishes() noexcept { __tsan_release(&to_tasks); }
  static void task_receives() noexcept { __tsan_acquire(&to_tasks); }
  static void task_publishes() noexcept { __tsan_release(&to_caller); }
  static void caller_receives() noexcept { __tsan_acquire(&to_caller); }
  static inline char to_tasks = 0, to_caller = 0;
#else
  static void caller_publishes() noexcept {}
  static void task_receives() noexcept {}
  static void task_publishes() noexcept {}
  static void caller_receives() noexcept {}
#endif
};

}  // namespace trivox::detail
