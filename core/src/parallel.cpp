#include "weft/core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace weft {

int hardware_threads() {
  return tbb::info::default_concurrency();
}

int thread_count(int threads) {
  return threads > 0 ? threads : hardware_threads();
}

void parallel_for(uint64_t count, int threads, const std::function<void(uint64_t)>& fn) {
  if (count == 0) return;
  const int n = thread_count(threads);
  if (n == 1) {
    for (uint64_t i = 0; i < count; ++i) fn(i);
    return;
  }
  tbb::task_arena arena(n);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, count, 1),
                      [&](const tbb::blocked_range<uint64_t>& r) {
                        for (uint64_t i = r.begin(); i != r.end(); ++i) fn(i);
                      });
  });
}

}  // namespace weft
