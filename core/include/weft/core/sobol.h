#pragma once
// Randomised Sobol' points for stratified Monte Carlo: the first dimensions of the Sobol' sequence
// (direction numbers of Joe and Kuo 2008, "Constructing Sobol sequences with better
// two-dimensional projections"), Owen-scrambled per dimension by the hash of Burley 2020
// ("Practical Hash-based Owen Scrambling", JCGT 9(4)), then digitally shifted by a uniform random
// 53-bit word. The shift makes every single point uniform on the 2^-53 grid whatever the scramble
// (so an estimate over the points is as unbiased as one over Rng::uniform()), while the first
// 2^m points keep the sequence's stratification: in every dimension one point per interval of
// length 2^-m, and in dimensions (0, 1) one per elementary box of area 2^-m.
#include <array>
#include <cstdint>

#include "weft/core/rng.h"

namespace weft {

class ScrambledSobol {
 public:
  static constexpr int kDimensions = 6;

  // The scrambles and shifts drawn from 'rng' (deterministic given its stream).
  explicit ScrambledSobol(Rng& rng);

  // Coordinate 'dim' (0 .. kDimensions - 1) of point 'index', in [0, 1).
  double sample(uint32_t index, int dim) const;

  // The unscrambled sequence's coordinate as a 32-bit fraction (what the tests check).
  static uint32_t sobol_bits(uint32_t index, int dim);

 private:
  std::array<uint32_t, kDimensions> scramble_{};
  std::array<uint64_t, kDimensions> shift_{};
};

}  // namespace weft
