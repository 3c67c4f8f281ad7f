// The content hash (FNV-1a 64) against the published test vectors of the FNV reference: L. C.
// Noll, test_fnv.c of the FNV reference code (isthe.com/chongo/tech/comp/fnv), table
// fnv1a_64_vector for the strings "", "a", "foob", "foobar" (also listed in the IETF draft
// draft-eastlake-fnv, "FNV test vectors").
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "weft/core/hash.h"

using namespace weft;

TEST(Fnv1a64, PublishedTestVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foob"), 0xdd120e790c2512afULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
  // The empty input leaves the offset basis, as the reference defines it.
  EXPECT_EQ(fnv1a64(""), kFnv1a64Basis);
}

TEST(Fnv1a64, ContinuingAHashEqualsHashingTheConcatenation) {
  EXPECT_EQ(fnv1a64("bar", fnv1a64("foo")), fnv1a64("foobar"));
  const unsigned char bytes[] = {'f', 'o', 'o', 'b', 'a', 'r'};
  EXPECT_EQ(fnv1a64(bytes + 3, 3, fnv1a64(bytes, 3)), 0x85944171f73967e8ULL);
  // Embedded zero bytes are content, not terminators.
  EXPECT_NE(fnv1a64(std::string("a\0b", 3)), fnv1a64("a"));
}

TEST(Fnv1a64, UsableAtCompileTime) {
  constexpr unsigned char a[] = {'a'};
  static_assert(fnv1a64(a, 1) == 0xaf63dc4c8601ec8cULL);
  SUCCEED();
}

TEST(Hex64, SixteenLowerCaseDigits) {
  EXPECT_EQ(hex64(0x85944171f73967e8ULL), "85944171f73967e8");
  EXPECT_EQ(hex64(0), "0000000000000000");
  EXPECT_EQ(hex64(0xABCULL), "0000000000000abc");
  EXPECT_EQ(hex64(UINT64_MAX), "ffffffffffffffff");
}
