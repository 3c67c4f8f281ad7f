// Part files of sharded jobs (core/job_part.h): crafted counts are refused before anything is sized
// or looped over by them, and a part of another job (a stale part) is refused naming its file.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <string>

#include "mutate.h"
#include "test_util.h"
#include "weft/core/clock.h"
#include "weft/core/job_part.h"

namespace fs = std::filesystem;
using weft::testing::error_of;
using weft::testing::fresh_test_dir;

namespace weft {
namespace {

// A part's header with the given counts and no units listed, as a hostile user writes one.
nlohmann::json crafted_header(uint64_t units_total, uint64_t shard, uint64_t shards) {
  return {{"command", "bake fiber"},
          {"job", {{"seed", 1}}},
          {"units_total", units_total},
          {"shard", shard},
          {"shards", shards},
          {"checkpoint", false},
          {"extra", nlohmann::json::object()},
          {"units", nlohmann::json::array()},
          {"unit_doubles", nlohmann::json::array()}};
}

// The part file of a header and no payload.
fs::path write_part(const fs::path& p, const nlohmann::json& header) {
  std::ofstream(p, std::ios::binary) << "WEFT-PART 1\n" << header.dump() << "\n";
  return p;
}

fs::path crafted_part(const fs::path& dir, const std::string& name, uint64_t units_total,
                      uint64_t shard, uint64_t shards) {
  return write_part(dir / name, crafted_header(units_total, shard, shards));
}

double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return seconds_since(t0);
}

// units_total 2^40 and 4e9 shards: the merge looped over every shard (and listed the missing ones
// in a string of gigabytes); now both are refused as the header is read, naming the file and field.
TEST(JobPart, CraftedCountsAreRefusedAsTheHeaderIsRead) {
  const fs::path dir = fresh_test_dir();
  const fs::path units = crafted_part(dir, "units.part", uint64_t{1} << 40, 0, 1);
  const fs::path shards = crafted_part(dir, "shards.part", 2, 0, 4000000000u);
  std::string e;
  EXPECT_LT(seconds_of([&] { e = error_of([&] { merge_job_parts({units}); }); }), 1.0);
  EXPECT_NE(e.find(units.string() + ": field 'units_total'"), std::string::npos) << e;
  EXPECT_LT(seconds_of([&] { e = error_of([&] { merge_job_parts({shards}); }); }), 1.0);
  EXPECT_NE(e.find(shards.string() + ": field 'shards'"), std::string::npos) << e;
  // A list of units longer than units_total is refused before it is converted.
  nlohmann::json h = crafted_header(2, 0, 1);
  h["units"] = {0, 1, 2};
  h["unit_doubles"] = {0, 0, 0};
  const fs::path listed = write_part(dir / "listed.part", h);
  e = error_of([&] { read_job_part(listed); });
  EXPECT_NE(e.find(listed.string() + ": field 'units': has 3 entries, at most 2"),
            std::string::npos)
      << e;
  // At both limits a part reads.
  const fs::path empty = crafted_part(dir, "empty.part", kMaxJobUnits, 0, kMaxShards);
  EXPECT_EQ(read_job_part(empty).units_total, kMaxJobUnits);
}

// Counts written as numbers no 64-bit count holds (1e30, -1, 2^64) or as fractions were cast as
// they were read, which is undefined behaviour (the fuzzer found 1e30 in a list of units); now
// each is refused naming the file and the entry.
TEST(JobPart, CountsOutOfRangeAreRefusedBeforeTheyAreConverted) {
  const fs::path dir = fresh_test_dir();
  nlohmann::json valid = crafted_header(2, 0, 1);
  valid["units"] = {1};
  valid["unit_doubles"] = {0};
  const fs::path ok = write_part(dir / "ok.part", valid);
  EXPECT_EQ(read_job_part(ok).units.size(), 1u);
  struct Case {
    std::string field, shown;
    nlohmann::json value;
  };
  const std::vector<Case> cases = {{"units", "units[0]", {1e30}},
                                   {"units", "units[0]", {-1}},
                                   {"units", "units[0]", {1.5}},
                                   {"units", "units[0]", {2}},
                                   {"unit_doubles", "unit_doubles[0]", {18446744073709551616.0}},
                                   {"unit_doubles", "unit_doubles[0]", {"0"}},
                                   {"units_total", "units_total", 1e30},
                                   {"shard", "shard", -3},
                                   {"shards", "shards", 4.5},
                                   {"shard", "shard", 1}};
  for (const Case& c : cases) {
    nlohmann::json h = valid;
    h[c.field] = c.value;
    const fs::path p = write_part(dir / "crafted.part", h);
    const std::string e = error_of([&] { read_job_part(p); });
    EXPECT_NE(e.find(p.string() + ": field '" + c.shown + "'"), std::string::npos)
        << c.value.dump() << ": " << e;
  }
}

// A merge missing most of 100 000 shards names the first few and counts the rest.
TEST(JobPart, MissingShardsAreNamedBriefly) {
  const fs::path dir = fresh_test_dir();
  JobPart p;
  p.command = "bake fiber";
  p.job = {{"seed", 1}};
  p.units_total = kMaxShards;
  p.shard = {0, kMaxShards};
  p.units[0] = {1.0};
  write_job_part(dir / "p0", p);
  const std::string e = error_of([&] { merge_job_parts({dir / "p0"}); });
  EXPECT_NE(e.find("missing shard 1/100000, 2/100000"), std::string::npos) << e;
  EXPECT_NE(e.find(" more"), std::string::npos) << e;
  EXPECT_LT(e.size(), 200u) << e;
}

// A part left from an earlier run with other settings (a stale part) is refused, naming its file,
// the field 'job' and the setting that differs.
TEST(JobPart, StalePartIsRefusedNamingItsFile) {
  const fs::path dir = fresh_test_dir();
  JobPart p;
  p.command = "bake fiber";
  p.job = {{"seed", 1}, {"photons", 100}};
  p.units_total = 2;
  p.shard = {0, 2};
  p.units[0] = {1.0};
  write_job_part(dir / "p0", p);
  p.shard.index = 1;
  p.units = {{1, {2.0}}};
  write_job_part(dir / "p1", p);
  EXPECT_EQ(merge_job_parts({dir / "p0", dir / "p1"}).units.size(), 2u);
  p.job["photons"] = 200;
  write_job_part(dir / "stale", p);
  const std::string e = error_of([&] { merge_job_parts({dir / "p0", dir / "stale"}); });
  EXPECT_NE(e.find((dir / "stale").string() + ": field 'job': belongs to another job"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("setting 'photons' differs"), std::string::npos) << e;
}

// A damaged checkpoint is passed over (the run starts afresh) and its warning reaches the caller
// as a value, for the front end to show: the library itself prints nothing.
TEST(JobPart, UnreadableCheckpointIsReportedToTheCaller) {
  const fs::path dir = fresh_test_dir();
  JobPart job;
  job.command = "bake fiber";
  job.job = {{"seed", 1}};
  job.units_total = 2;
  job.shard = {0, 1};
  const fs::path out = dir / "table.exr";
  std::ofstream(checkpoint_path(out), std::ios::binary) << "WEFT-PART 1\nnot json\n";
  std::vector<std::string> warnings;
  ::testing::internal::CaptureStderr();
  const auto damaged = load_checkpoint(out, job, true, warnings);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_FALSE(damaged.has_value());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], checkpoint_path(out).string() + " is unreadable; starting afresh");
  // Without --resume the checkpoint is not read, and a readable one of this job has nothing to
  // report.
  warnings.clear();
  EXPECT_FALSE(load_checkpoint(out, job, false, warnings).has_value());
  JobPart saved = job;
  saved.checkpoint = true;
  saved.units[1] = {0.5};
  write_job_part(checkpoint_path(out), saved);
  const auto resumed = load_checkpoint(out, job, true, warnings);
  ASSERT_TRUE(resumed.has_value());
  EXPECT_EQ(resumed->units.at(1), std::vector<double>{0.5});
  EXPECT_TRUE(warnings.empty());
}

// Random byte edits of a valid part file (its magic line, JSON header and raw doubles), seeded:
// every mutant is read or refused with a weft::Error naming the file.
TEST(JobPart, ByteMutationsAreReadOrRefusedNeverCrash) {
  const fs::path dir = fresh_test_dir();
  JobPart p;
  p.command = "bake fiber";
  p.job = {{"seed", 1}, {"photons", 100}, {"name", "red-cotton"}};
  p.units_total = 33;
  p.shard = {1, 4};
  for (uint64_t u = 8; u < 16; ++u) p.units[u] = {double(u), 0.5, -1.25};
  write_job_part(dir / "valid", p);
  const std::string valid = testing::slurp(dir / "valid");
  Rng rng(20261203);
  int read = 0, refused = 0;
  const fs::path path = dir / "mutant.part";
  for (int trial = 0; trial < 200; ++trial) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << testing::mutated(valid, rng);
    try {
      const JobPart m = read_job_part(path);
      EXPECT_LE(m.units.size(), m.units_total);
      ++read;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      ++refused;
    }
  }
  EXPECT_GT(read, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace weft
