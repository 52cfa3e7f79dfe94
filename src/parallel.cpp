#include "trivox/parallel.h"

#include <algorithm>
#include <thread>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "tsan_handoff.h"

namespace trivox {

int worker_count(int threads) noexcept {
  return threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void parallel_for_each(std::size_t count, int threads, const std::function<void(std::size_t)>& task,
                       const std::function<bool()>& stop) {
  tbb::task_arena arena(worker_count(threads));
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
