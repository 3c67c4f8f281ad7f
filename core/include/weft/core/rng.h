#pragma once
// PCG32 random streams. Every stream is derived from (seed, task index) through a strong 64-bit
// mix, never from thread identity or time, so results are bit-identical at any thread count.
#include <cstdint>

namespace weft {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Rng {
 public:
  // A stream for one task: 'task' is e.g. a photon-batch index or a pixel index, 'sub' an optional
  // second index (sample number). Distinct (seed, task, sub) give independent streams.
  explicit Rng(uint64_t seed = 0, uint64_t task = 0, uint64_t sub = 0) {
    const uint64_t a = mix64(seed ^ mix64(task + 0x632be59bd9b4e019ULL));
    const uint64_t b = mix64(a ^ mix64(sub + 0x85157af5ULL));
    inc_ = (b << 1u) | 1u;
    state_ = 0;
    next_u32();
    state_ += a;
    next_u32();
  }

  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() {
    const uint64_t hi = next_u32() >> 5;  // 27 bits
    const uint64_t lo = next_u32() >> 6;  // 26 bits
    return static_cast<double>((hi << 26) | lo) * 0x1.0p-53;
  }
  // Uniform in (0, 1]: safe for -log(u).
  double uniform_open0() { return 1.0 - uniform(); }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

}  // namespace weft
