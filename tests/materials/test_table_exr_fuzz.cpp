// Inputs that fuzz_table_exr (tests/fuzz) found to crash, exhaust memory or run for seconds, kept
// in tests/fuzz/regressions/table: each must now be a weft::Error naming the file, at once.
#include <gtest/gtest.h>

#include <filesystem>

#include "test_util.h"
#include "weft/materials/bsdf_table.h"

using weft::testing::error_of;
namespace fs = std::filesystem;

TEST(TableExrFuzzRegressions, EveryFoundInputIsAClearError) {
  const fs::path dir = fs::path(WEFT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "table";
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string msg = error_of([&] { weft::TabulatedBsdfTable::read_exr(e.path()); });
    EXPECT_EQ(msg.rfind(e.path().string() + ": ", 0), 0u) << msg;
    ++n;
  }
  // oom-chlist-out-of-step.exr: a channel list whose entries end before its size field says,
  // then a 272-byte "box2i" data window; OpenEXR read on out of step into a string of 1.95 GB.
  // string-claims-1.8GB.exr: a string attribute whose size field is text ("ocal"): 1.8 GB.
  // slow-unit-1.exr: took 14 s under ASan before the header checks.
  EXPECT_EQ(n, 3);
}
