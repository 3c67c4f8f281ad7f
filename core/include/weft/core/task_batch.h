#pragma once
// The one deterministic batch runner of the project (photon bakes, the ray-traced fabric
// estimator). Work items are split into fixed-size tasks; task k draws from Rng(seed, k) and fills
// its own tally; tallies are merged in task order. So the result has the same bits at any thread
// count. Tasks run in waves; between waves the progress callback is called on the calling thread
// and may cancel: the tasks done so far are kept, and the status says how many items they hold.
#include <algorithm>
#include <cstdint>
#include <string_view>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"

namespace weft {

struct TaskBatch {
  uint64_t items = 0;
  uint64_t seed = 0;
  int threads = 0;                 // 0: all hardware threads
  uint64_t items_per_task = 4096;  // fixes the random streams: change it, change the bits
  uint64_t tasks_per_wave = 0;     // 0: 8 per core used; lower it when tallies are large
  ProgressCallback progress;       // may be empty
  std::string_view stage = "items";

  void validate() const {
    if (items_per_task == 0) throw Error("", "items_per_task", "must be >= 1");
    if (threads < 0) throw Error("", "threads", "must be >= 0");
  }
};

struct TaskBatchStatus {
  uint64_t items_done = 0;
  uint64_t tasks_done = 0;
  bool cancelled = false;
};

// Runs run(task, first_item, count, rng, tally) for every task, each on a default-constructed
// TaskTally, and hands the tallies to merge(tally) in task order. Exceptions from run propagate.
template <class TaskTally, class Run, class Merge>
TaskBatchStatus run_batch(const TaskBatch& batch, Run&& run, Merge&& merge) {
  batch.validate();
  const uint64_t per_task = batch.items_per_task;
  const uint64_t tasks = batch.items / per_task + (batch.items % per_task != 0 ? 1 : 0);
  const int threads = thread_count(batch.threads);
  // A wave is 8 tasks per core the threads run on, not per thread: more threads than cores share
  // them, so a wave, and the time between two calls of the progress callback, stays the same.
  const uint64_t wave = batch.tasks_per_wave > 0
                            ? batch.tasks_per_wave
                            : 8 * static_cast<uint64_t>(std::min(threads, hardware_threads()));
  TaskBatchStatus status;
  // A first report before any work starts the front end's clock and allows an early stop.
  if (batch.progress && !batch.progress(ProgressUpdate{batch.stage, 0, batch.items})) {
    status.cancelled = tasks > 0;
    return status;
  }
  std::vector<TaskTally> tallies;
  for (uint64_t start = 0; start < tasks; start += wave) {
    const uint64_t n = std::min(wave, tasks - start);
    tallies.assign(n, TaskTally{});
    parallel_for(n, threads, [&](uint64_t i) {
      const uint64_t task = start + i;
      const uint64_t first = task * per_task;
      const uint64_t count = std::min(per_task, batch.items - first);
      Rng rng(batch.seed, task);
      run(task, first, count, rng, tallies[i]);
    });
    for (uint64_t i = 0; i < n; ++i) merge(tallies[i]);
    status.tasks_done = start + n;
    status.items_done = std::min(batch.items, status.tasks_done * per_task);
    if (batch.progress &&
        !batch.progress(ProgressUpdate{batch.stage, status.items_done, batch.items})) {
      status.cancelled = status.tasks_done < tasks;
      break;
    }
  }
  return status;
}

}  // namespace weft
