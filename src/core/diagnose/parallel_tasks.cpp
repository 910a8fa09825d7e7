// Runs independent tasks on a few threads (parallel_tasks.h): each worker takes the next
// unstarted index until none is left; the calling thread is one of the workers.
#include "cvg_bench/core/diagnose/parallel_tasks.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace cvg_bench {

int taskThreads(int requested, size_t tasks) {
  int n = requested > 0 ? requested : static_cast<int>(std::thread::hardware_concurrency());
  n = std::max(1, n);
  return static_cast<int>(std::min<size_t>(static_cast<size_t>(n), std::max<size_t>(1, tasks)));
}

void runTasks(size_t count, int threads, const std::function<void(size_t)>& task) {
  const int n = taskThreads(threads, count);
  std::atomic<size_t> next{0};
  auto worker = [&]() {
    for (size_t i = next++; i < count; i = next++) task(i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace cvg_bench
