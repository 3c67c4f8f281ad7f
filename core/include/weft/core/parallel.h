#pragma once
// Deterministic task parallelism. Work is split into tasks by index; each task derives its random
// stream from (seed, task index), and results are combined in task order, so any thread count
// gives the same bits.
#include <cstdint>
#include <functional>

namespace weft {

// Runs fn(task) for task in [0, count) on at most 'threads' threads (0 = all cores).
// Tasks are independent; fn must not depend on which thread runs it.
// Exceptions thrown by fn propagate (the first one wins).
void parallel_for(uint64_t count, int threads, const std::function<void(uint64_t task)>& fn);

// Number of hardware threads.
int hardware_threads();
// The threads a request for 'threads' runs on: 'threads', or all cores for 0 (or less).
int thread_count(int threads);

}  // namespace weft
