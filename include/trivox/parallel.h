// The library's one parallel seam: every loop that runs on several threads goes through
// parallel_for_each (today the slice job's loop over layers). Behind it, oneTBB's
// parallel_for in a task arena of the requested size; nothing else in the library names
// TBB, so a change of scheduler, a sequential build or a new kind of cancellation is made
// here.
#pragma once

#include <cstddef>
#include <functional>

namespace trivox {

// The most workers a job runs on: 4 per hardware thread, at most 1024. More would only add
// memory (each holds a layer) and contention.
int max_worker_count() noexcept;

// The number of workers a `threads` setting means: `threads` itself when positive (at most
// max_worker_count()), else every core (at least 1).
int worker_count(int threads) noexcept;

// Runs task(i) for every i in [0, count) on worker_count(threads) workers (more than the
// cores when asked: oneTBB is allowed that many for the call), in any order and
// several at once: each task must touch only its own data (or guard what it shares). Before
// each task starts, `stop` (when given) is asked; once it answers true, no further task
// starts and those running finish. Returns when every started task has ended; the first
// exception a task throws is rethrown here, after the others have ended.
void parallel_for_each(std::size_t count, int threads, const std::function<void(std::size_t)>& task,
                       const std::function<bool()>& stop = {});

}  // namespace trivox
