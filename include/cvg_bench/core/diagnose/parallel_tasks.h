// Independent tasks of one selection step (candidate fits, hold-outs) run on several threads.
// Task i writes only its own result slot, so the results are the same for any thread count and
// are used by the caller in task order.
#pragma once

#include <cstddef>
#include <functional>

namespace cvg_bench {

/// Threads to use for `requested` (0: the machine's cores, at least 1), never more than `tasks`.
int taskThreads(int requested, size_t tasks);

/// Runs task(0) .. task(count - 1), up to `threads` at a time (taskThreads), and returns when all
/// are done. A task must not throw (catch inside it and store the error in its slot).
void runTasks(size_t count, int threads, const std::function<void(size_t)>& task);

}  // namespace cvg_bench
