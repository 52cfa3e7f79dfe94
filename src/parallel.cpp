#include "trivox/parallel.h"

#include <algorithm>
#include <optional>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "tsan_handoff.h"

namespace trivox {

namespace {
int hardware_threads() noexcept { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }
}  // namespace

int max_worker_count() noexcept { return std::min(1024, 4 * hardware_threads()); }

int worker_count(int threads) noexcept {
  return threads > 0 ? std::min(threads, max_worker_count()) : hardware_threads();
}

void parallel_for_each(std::size_t count, int threads, const std::function<void(std::size_t)>& task,
                       const std::function<bool()>& stop) {
  const int workers = worker_count(threads);
  // oneTBB runs no more threads than the cores unless allowed (and warns on standard error,
  // "TBB Warning: The number of workers is currently limited to ..."): allowed here for the
  // call, so that the job runs on the count it reports.
  std::optional<tbb::global_control> allow;
  if (workers > tbb::this_task_arena::max_concurrency())
    allow.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(workers));
  tbb::task_arena arena(workers);
  // parallel_for keeps a reference to run_one, so it is made before the tasks are handed
  // their data (tsan_handoff.h).
  auto run_one = [&](std::size_t i) {
    detail::TsanHandoff::task_receives();
    struct PublishAtEnd {
      ~PublishAtEnd() { detail::TsanHandoff::task_publishes(); }
    } publish_at_end;
    if (stop && stop()) return;
    task(i);
  };
  auto run_all = [&] { tbb::parallel_for(std::size_t{0}, count, run_one); };
  detail::TsanHandoff::caller_publishes();
  arena.execute(run_all);
  detail::TsanHandoff::caller_receives();
}

}  // namespace trivox
