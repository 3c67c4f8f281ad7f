// The progress line a log shows: plain text, percent, a rate with its unit, an ETA.
#include <gtest/gtest.h>

#include <cmath>

#include "weft/core/progress.h"

using namespace weft;

TEST(Progress, DurationsInMinutesAndHours) {
  EXPECT_EQ(format_duration(0), "00:00");
  EXPECT_EQ(format_duration(61.4), "01:01");
  EXPECT_EQ(format_duration(3599.4), "59:59");
  EXPECT_EQ(format_duration(3723), "1:02:03");
  EXPECT_EQ(format_duration(-1), "--:--");
  EXPECT_EQ(format_duration(NAN), "--:--");
  EXPECT_EQ(format_duration(INFINITY), "--:--");
}

TEST(Progress, RatesCarryAnSiPrefixAndTheirUnit) {
  EXPECT_EQ(format_rate(0, "samples"), "0 samples/s");
  EXPECT_EQ(format_rate(512, "photons"), "512 photons/s");
  EXPECT_EQ(format_rate(1234.5, "rays"), "1.23 k rays/s");
  EXPECT_EQ(format_rate(12345, "rays"), "12.3 k rays/s");
  EXPECT_EQ(format_rate(2.5e6, "samples"), "2.50 M samples/s");
  EXPECT_EQ(format_rate(3.21e9, "rays"), "3.21 G rays/s");
  EXPECT_EQ(format_rate(7, ""), "7 units/s");
  EXPECT_EQ(format_rate(NAN, "rays"), "-- rays/s");
}

TEST(Progress, LineHasPercentRateUnitAndEta) {
  // 450 of 1000 samples in 9 s: 50 samples/s, 550 left -> 11 s.
  const ProgressUpdate u{"render", 450, 1000, "samples"};
  EXPECT_EQ(format_progress_line(u, 9.0), "render   45.0%  50 samples/s  ETA 00:11");
}

TEST(Progress, StageNamesTheUnitWhenNoneIsGiven) {
  const ProgressUpdate u{"photons", 3000, 6000};
  EXPECT_EQ(format_progress_line(u, 2.0), "photons   50.0%  1.50 k photons/s  ETA 00:02");
}

TEST(Progress, UnknownTotalHasNoPercentNorEta) {
  const ProgressUpdate u{"medium", 4, 0, "bands"};
  EXPECT_EQ(format_progress_line(u, 2.0), "medium  2 bands/s");
}

TEST(Progress, NoEtaBeforeTheFirstUnitAndNoCarriageReturn) {
  const ProgressUpdate u{"render", 0, 100, "samples"};
  const std::string line = format_progress_line(u, 0.0);
  EXPECT_EQ(line, "render    0.0%  0 samples/s  ETA --:--");
  EXPECT_EQ(line.find('\r'), std::string::npos);
  EXPECT_EQ(line.find('\n'), std::string::npos);
}
