// The ray trace's paths recorded under a proposal and re-weighted for another fiber table
// (weft/fabric/recorded_paths.h): the same bits as tracing that table with the proposal.
#include <gtest/gtest.h>

#include <string>

#include "raytrace_test_util.h"
#include "weft/core/error.h"
#include "weft/fabric/recorded_paths.h"

namespace weft {
namespace {

using testing::default_sample;
using testing::fiber_table3;
using testing::options;
using testing::reciprocal_fiber;

// A coloured table unlike the proposal (ProposalReweightingIsUnbiased's proposal): the weights of
// the re-weighted paths differ from the proposal's in every channel.
TabulatedBsdfTable coloured_fiber(int resolution) {
  return fiber_table3(resolution, [](const Vec3& wo, const Vec3& wi, std::span<double> v) {
    const double shape = (wo.z > 0 ? 1.0 : 0.3) * (1 + 0.5 * wo.z * wi.z) * kInvPi;
    v[0] = 0.3 * shape, v[1] = 0.15 * shape, v[2] = 0.08 * shape;
  });
}

void expect_same_bits(const FabricRaytraceResult& a, const FabricRaytraceResult& b,
                      const std::string& what) {
  EXPECT_EQ(a.table.values, b.table.values) << what;
  EXPECT_EQ(a.standard_error, b.standard_error) << what;
  EXPECT_EQ(a.relative_noise, b.relative_noise) << what;
  EXPECT_EQ(a.table.metadata, b.table.metadata) << what;
  EXPECT_EQ(a.particles, b.particles) << what;
  EXPECT_EQ(a.scatterings, b.scatterings) << what;
  EXPECT_EQ(a.splits, b.splits) << what;
  EXPECT_EQ(a.roulette_kills, b.roulette_kills) << what;
}

// Fiber detail (the verify fit's) and yarn tubes (their line albedo replayed), the default
// estimator (computed straight-through light, which the record keeps) and launch blocks with the
// straight-through light sampled (the particles book it): the re-weighted table of a table other
// than the proposal has the bits of the trace of that table with the proposal, at another thread
// count; the record's own trace is that of the proposal.
TEST(FabricRecordedPaths, ReweightedPathsHaveTheBitsOfTheTraceWithTheProposal) {
  const TabulatedBsdfTable proposal = reciprocal_fiber(4), fiber = coloured_fiber(4);
  for (const char* detail : {"fiber", "yarn"})
    for (const bool blocks : {false, true}) {
      const std::string what = std::string(detail) + (blocks ? ", launch blocks, sampled" : "");
      const WovenSample sample = default_sample(detail);
      FabricRaytraceOptions o = options(3, 600);
      o.threads = 2;
      if (blocks) {
        o.launch_lattice = 8;
        o.straight_through = StraightThrough::sampled;
      }
      const RecordedFabricPaths paths = record_fabric_paths(sample, proposal, o);
      o.proposal = &proposal;
      const FabricRaytraceResult traced = raytrace_fabric_table(sample, fiber, o);
      const FabricRaytraceResult reweighted = reweight_fabric_paths(paths, fiber, 1);
      expect_same_bits(reweighted, traced, what);
      EXPECT_GT(reweighted.splits + reweighted.roulette_kills, 0u) << what;  // both replayed
      EXPECT_NE(reweighted.table.values, paths.traced.table.values) << what;
      EXPECT_EQ(reweighted.exited, 0.0) << what;  // the energy books are not replayed
      expect_same_bits(paths.traced, raytrace_fabric_table(sample, proposal, o), what);
      expect_same_bits(reweight_fabric_paths(paths, proposal, 3), paths.traced, what);
    }
}

// What the record does not replay is refused by name, and so is a table that does not fit it.
TEST(FabricRecordedPaths, WhatIsNotRecordedIsRefused) {
  const TabulatedBsdfTable proposal = reciprocal_fiber(4);
  const WovenSample sample = default_sample("fiber");
  auto field_of = [&](FabricRaytraceOptions o) -> std::string {
    try {
      (void)record_fabric_paths(sample, proposal, o);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  FabricRaytraceOptions o = options(3, 20);
  o.bin_count = 2;
  EXPECT_NE(field_of(o).find("field 'bin_count'"), std::string::npos);
  o = options(3, 20);
  o.next_event_rays = 2;
  EXPECT_NE(field_of(o).find("field 'next_event_rays'"), std::string::npos);
  o = options(3, 20);
  o.weave_positions_u = o.weave_positions_v = 2;
  EXPECT_NE(field_of(o).find("field 'weave_positions_u'"), std::string::npos);
  const RecordedFabricPaths paths = record_fabric_paths(sample, proposal, options(3, 20));
  EXPECT_THROW((void)reweight_fabric_paths(paths, reciprocal_fiber(3)), Error);
}

}  // namespace
}  // namespace weft
