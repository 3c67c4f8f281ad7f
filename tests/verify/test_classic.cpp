// The classic baseline's colour (verify/classic.h): the reflectance that stands for a fiber's
// volume albedo makes the classic fiber send out as much light in all as that fiber.
#include <gtest/gtest.h>

#include "weft/materials/classic_fiber.h"
#include "weft/verify/classic.h"

namespace weft {
namespace {

constexpr MicrofacetDistribution kCotton{MicrofacetModel::kBeckmann, 0.35};
constexpr double kCottonIndex = 1.557;

// The lobe alone, tabulated at R = 16 (4 samples per cell pair), returns 0.0729 of the light
// hitting it (docs/verify.md, within 0.0002 of R = 24): the share past it is 1 - 0.0729.
TEST(VerifyClassic, ShareEnteringIsWhatTheTabulatedLobeLeaves) {
  const double lobe =
      classic_fiber_table(Rgb(0.0), kCotton, kCottonIndex, 16, 4, 1, 0).total_albedo()[0];
  EXPECT_NEAR(lobe, 0.0729, 0.0002);
  EXPECT_NEAR(classic_entering_fraction(kCotton, kCottonIndex), 1 - lobe, 0.0005);
}

// A fiber whose volume returns V of all light and whose surface returns E_avg sends out
// E_avg + V; the classic fiber with reflectance V / (1 - E_avg) must send out the same (its
// table's total albedo, R = 16). With V itself it would be darker by V E_avg (0.04 here): the
// tolerance, 0.002, is the tabulation's (0.0002 for the lobe, 0.5 % of the volume part).
TEST(VerifyClassic, ReflectanceFromTheVolumeAlbedoSendsOutWhatTheFiberDoes) {
  const double entering = classic_entering_fraction(kCotton, kCottonIndex);
  const Rgb volume(0.8, 0.3, 0.05);
  const Rgb reflectance(volume.r / entering, volume.g / entering, volume.b / entering);
  const auto total =
      classic_fiber_table(reflectance, kCotton, kCottonIndex, 16, 4, 1, 0).total_albedo();
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(total[k], (1 - entering) + volume[k], 0.002) << "channel " << k;
  // Rougher and smoother surfaces leave other shares; all are in (0, 1).
  for (double alpha : {0.05, 0.35, 1.0}) {
    const double e = classic_entering_fraction({MicrofacetModel::kGgx, alpha}, 1.5);
    EXPECT_GT(e, 0.85) << alpha;
    EXPECT_LT(e, 1.0) << alpha;
  }
}

}  // namespace
}  // namespace weft
