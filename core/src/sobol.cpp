#include "weft/core/sobol.h"

#include "weft/core/error.h"

namespace weft {
namespace {

using GeneratorMatrix = std::array<uint32_t, 32>;

// Direction numbers v_k (k = 1 .. 32, as 32-bit fractions) of a dimension with primitive
// polynomial of degree s, inner coefficients a (Joe and Kuo's encoding) and initial m_1 .. m_s.
constexpr GeneratorMatrix direction_numbers(int s, uint32_t a, std::array<uint32_t, 4> m) {
  GeneratorMatrix v{};
  for (int k = 0; k < s; ++k) v[k] = m[k] << (31 - k);
  for (int k = s; k < 32; ++k) {
    v[k] = v[k - s] ^ (v[k - s] >> s);
    for (int j = 1; j < s; ++j)
      if ((a >> (s - 1 - j)) & 1u) v[k] ^= v[k - j];
  }
  return v;
}

constexpr GeneratorMatrix van_der_corput() {
  GeneratorMatrix v{};
  for (int k = 0; k < 32; ++k) v[k] = 1u << (31 - k);
  return v;
}

// Dimensions 1 .. 5 from Joe and Kuo's new-joe-kuo-6.21201 table (d = 2 .. 6).
constexpr std::array<GeneratorMatrix, ScrambledSobol::kDimensions> kMatrices = {
    van_der_corput(),
    direction_numbers(1, 0, {1}),
    direction_numbers(2, 1, {1, 3}),
    direction_numbers(3, 1, {1, 3, 1}),
    direction_numbers(3, 2, {1, 1, 1}),
    direction_numbers(4, 1, {1, 1, 3, 3}),
};

uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Burley's nested uniform scramble: each bit flipped by a hash of the bits above it, which
// permutes every elementary interval's halves (an Owen scramble) and so keeps the stratification.
uint32_t owen_scramble(uint32_t x, uint32_t seed) {
  x = reverse_bits(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return reverse_bits(x);
}

// The sequence's coordinate without the range check (the hot path of sample()).
uint32_t sobol_unchecked(uint32_t index, int dim) {
  uint32_t x = 0;
  for (const uint32_t* v = kMatrices[dim].data(); index != 0; index >>= 1, ++v)
    if (index & 1u) x ^= *v;
  return x;
}

}  // namespace

ScrambledSobol::ScrambledSobol(Rng& rng) {
  for (int d = 0; d < kDimensions; ++d) {
    scramble_[d] = rng.next_u32();
    shift_[d] = (static_cast<uint64_t>(rng.next_u32()) << 21) ^ (rng.next_u32() >> 11);
  }
}

uint32_t ScrambledSobol::sobol_bits(uint32_t index, int dim) {
  if (dim < 0 || dim >= kDimensions) throw Error("", "dim", "Sobol' dimension out of range");
  return sobol_unchecked(index, dim);
}

double ScrambledSobol::sample(uint32_t index, int dim) const {
  if (dim < 0 || dim >= kDimensions) throw Error("", "dim", "Sobol' dimension out of range");
  const uint64_t bits = owen_scramble(sobol_unchecked(index, dim), scramble_[dim]);
  // 32 scrambled digits above 21 zero ones, shifted by a uniform 53-bit word: the point is uniform
  // on the 2^-53 grid (its low digits are the shift's, the same for every point of the set).
  return static_cast<double>((bits << 21) ^ shift_[dim]) * 0x1.0p-53;
}

}  // namespace weft
