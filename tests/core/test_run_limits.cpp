// The limits a request carries (core/run_limits.h), the output guard's record of inputs
// (core/output_guard.h) and the name tables of users' choices (core/names.h): no process-wide
// state, so two requests with different limits in one process do not see each other's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_util.h"
#include "weft/core/names.h"
#include "weft/core/output_guard.h"
#include "weft/core/run_limits.h"

using namespace weft;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace {

// 7200 s of work on one core: above an hour, so it needs consent.
void two_hours(const RunLimits& l) {
  check_long_work(l, 7200, 1.0, 1, "f.json", "photons", "a bake", "1 s per unit");
}

}  // namespace

TEST(RunLimits, LongWorkNeedsConsentOfItsOwnRequest) {
  RunLimits refused, allowed;
  allowed.yes_long = true;
  const std::string e = error_of([&] { two_hours(refused); });
  EXPECT_NE(e.find("would take at least 2.0 h"), std::string::npos) << e;
  EXPECT_NE(e.find("add --yes-long"), std::string::npos) << e;
  EXPECT_NE(e.find("photons"), std::string::npos) << e;
  EXPECT_NO_THROW(two_hours(allowed));
  // The refusal did not change the other request's limits, nor the allowance this one's.
  EXPECT_FALSE(refused.yes_long);
  EXPECT_THROW(two_hours(refused), Error);
}

TEST(RunLimits, WorkAboveAMinuteIsAnnouncedThroughTheRequestsHook) {
  std::vector<std::string> lines;
  RunLimits l;
  l.announce = [&](const std::string& s) { lines.push_back(s); };
  check_long_work(l, 30, 1.0, 1, "", "", "short work", "1 s per unit");
  EXPECT_TRUE(lines.empty());
  check_long_work(l, 90, 1.0, 1, "", "", "a sweep", "1 s per unit");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "a sweep: at least 90 s (1 s per unit, 1 core)");
  RunLimits silent;  // no hook: nothing announced, nothing thrown below an hour
  EXPECT_NO_THROW(check_long_work(silent, 90, 1.0, 1, "", "", "a sweep", "1 s per unit"));
}

TEST(RunLimits, MemoryBudgetIsTheRequestsOrNoneInACheckOnlyRun) {
  RunLimits l;
  l.max_memory_bytes = 1e9;
  EXPECT_EQ(memory_budget_bytes(l), 1e9);
  const std::string e = error_of([&] { check_memory(l, 2e9, "s.json", "width", "a render"); });
  EXPECT_NE(e.find("a render needs about 2.0 GB of memory, more than the 1.0 GB allowed by "
                   "--max-memory-gb"),
            std::string::npos)
      << e;
  EXPECT_NO_THROW(check_memory(l, 0.5e9, "s.json", "width", "a render"));
  RunLimits check;
  check.check_only = true;  // the cluster's memory is not this machine's
  EXPECT_EQ(memory_budget_bytes(check), 0);
  EXPECT_NO_THROW(check_memory(check, 1e30, "", "", "anything"));
  EXPECT_THROW(work_starts(check), WorkWouldStart);
  EXPECT_NO_THROW(work_starts(RunLimits{}));
}

TEST(RunLimits, OutputGuardRecordsInputsOnlyWhereTheRequestAsks) {
  const auto dir = fresh_test_dir();
  const auto in = dir / "in.json";
  std::ofstream(in) << "{}";
  RunLimits plain, recording;
  recording.guarded_inputs = std::make_shared<std::vector<NamedPath>>();
  validate_output_paths(plain, {{dir / "out.exr", "--output"}}, {{in, "spec"}});
  validate_output_paths(recording, {{dir / "out.exr", "--output"}}, {{in, "spec"}});
  ASSERT_EQ(recording.guarded_inputs->size(), 1u);
  EXPECT_EQ(recording.guarded_inputs->front().what, "spec");
  EXPECT_THROW(validate_output_paths(plain, {{in, "--output"}}, {{in, "spec"}}), Error);
}

namespace {
enum class Colour { kRed, kGreen, kBlue };
constexpr NameTable<Colour, 3> kColours{{{Colour::kRed, "red", "Red"},
                                         {Colour::kGreen, "green", "Green"},
                                         {Colour::kBlue, "blue", "Blue"}}};
}  // namespace

TEST(Names, OneTableGivesNamesLabelsAndValuesAndListsTheValidNames) {
  EXPECT_EQ(value_of(kColours, "green", "", "colour"), Colour::kGreen);
  EXPECT_STREQ(name_of(kColours, Colour::kBlue), "blue");
  EXPECT_STREQ(label_of(kColours, Colour::kRed), "Red");
  EXPECT_EQ(names_of(kColours), (std::vector<std::string>{"red", "green", "blue"}));
  const std::string e = error_of([] { value_of(kColours, "mauve", "f.json", "colour"); });
  EXPECT_NE(e.find("must be 'red', 'green' or 'blue', got 'mauve'"), std::string::npos) << e;
  EXPECT_NE(e.find("colour"), std::string::npos) << e;
}
