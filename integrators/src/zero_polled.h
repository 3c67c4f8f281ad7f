#pragma once
// Large zeroed buffers made a slice at a time with a poll between slices: one image of a 16384 x
// 16384 film is 3.2 GB, and zeroing it in one call took seconds in which a Ctrl-C went unseen.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace weft {

// 'v' resized to 'n' zeros, its capacity reserved first (untouched pages cost nothing), then
// zeroed in slices of 8 MB with keep_going() asked after each. New pages came at only 60-80 MB/s
// on the project's shared 2-core machine (2026-12-05: a 16384 x 16384 film's 3.2 GB took 41 s),
// so a slice is about 0.1 s there. False as soon as it says stop, 'v' then only partly sized.
template <class T, class KeepGoing>
bool zero_polled(std::vector<T>& v, size_t n, KeepGoing&& keep_going) {
  constexpr size_t kSliceBytes = size_t(8) << 20;
  constexpr size_t kSlice = std::max<size_t>(1, kSliceBytes / sizeof(T));
  v.clear();
  v.reserve(n);
  while (v.size() < n) {
    v.resize(std::min(n, v.size() + kSlice));
    if (!keep_going()) return false;
  }
  return true;
}

}  // namespace weft
