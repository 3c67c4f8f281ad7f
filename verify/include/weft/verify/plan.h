#pragma once
// weft verify's request and its plan (docs/verify.md): what a user asks for, with the run's
// defaults (a front end binds these fields as they are); the inputs read and checked from it
// before any work; the time the run will take; a sharded run's job; and the classic baseline of a
// baked fiber table.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/colour_target.h"
#include "weft/core/job_part.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/verify/fit_models.h"
#include "weft/verify/verify.h"

namespace weft {

// --fit-seeds: the inner seeds each model is fitted at by default, and the most a request may ask.
inline constexpr int kDefaultFitSeeds = 3;
inline constexpr int kMaxFitSeeds = 16;

// What a user asks of weft verify. Paths are as given; empty strings are options not given.
struct VerifyRequest {
  std::string measured;      // measured in-plane table (empty: the bundled MERL red fabric)
  std::string colour_space;  // the table's RGB space, "srgb" or "camera" (empty: its comment line)
  std::string fiber = "red-cotton";  // fiber spec (.json) or preset, or a baked fiber table (.exr)
  std::string weave;                 // woven sample options (.json; empty: the bundled poplin)
  std::string pattern, wif;          // weave pattern or WIF draft over the sample's (one of them)
  std::string quality = quality_name(VerifySettings{}.quality);
  std::string output;  // the report folder, or a shard's part file
  uint64_t seed = VerifySettings{}.seed;
  int threads = VerifySettings{}.threads;  // 0 = all cores; results do not depend on it
  std::string classic_albedo;              // "R,G,B" (empty: from the fiber)
  // The cloth's colour (any --colour form, materials/colour_reading.h): the spec's dyes are
  // scaled to meet it before the run (docs/colour.md); empty: the recipe as written.
  std::string colour;
  // "measured": the colour is the measurement's own d/8 reading (its neural fit at 8 degrees),
  // and the computed model's absolute figure is then its calibrated one; empty: none.
  std::string colour_from;
  std::string shard;  // "K/N" (empty: the whole run)
  bool fit = false;
  std::string fit_params = spec_fit_parameter_list(",");  // every parameter
  int fit_evaluations = FitOptions{}.max_evaluations;
  std::string fit_inner = fit_inner_name(FitInnerSettings{}.inner);
  std::string fit_method = fit_method_name(FitOptions{}.method);
  // Each model is fitted this many times, each at its own inner seed and from its own start
  // (fit_start_of), and the best of the fits kept (fit_over_seeds): one search finds the first
  // minimum of one realization of the inner model's noise.
  int fit_seeds = kDefaultFitSeeds;
  // Which fit options the user gave: each is refused without 'fit'.
  bool fit_params_given = false, fit_evaluations_given = false, fit_inner_given = false,
       fit_method_given = false, fit_seeds_given = false;
};

// The request's inputs, read and checked before any work (every way of running verify starts
// here).
struct VerifyPlan {
  VerifyRequest request;
  VerifySettings settings;  // the quality's, with the request's seed and threads
  std::filesystem::path measured_path;
  MeasuredInplane measured;
  FiberSpec spec;                                 // when the fiber is a spec or preset
  std::optional<TabulatedBsdfTable> fiber_table;  // when it is a baked table (.exr)
  std::optional<Rgb> classic_albedo;
  std::optional<ColourTarget> colour;  // --colour, or the measurement's reading (--colour-from)
  WeaveOptions weave;
  std::optional<Shard> shard;  // a sharded run's
  std::vector<std::string> fit_names;
  FitOptions fit_options;
  FitInner fit_inner = FitInner::kRaytrace;
  int fit_seeds = kDefaultFitSeeds;
};

// weft::Error naming the option (or the file and field) at fault: an unreadable measurement,
// spec or table, both a pattern and a draft, bad fit options or fit options without the fit, the
// fit with a table or with shards, a bad shard.
VerifyPlan plan_verify(const VerifyRequest& request);

// "R,G,B", each a reflectance in [0, 1]; weft::Error naming "--classic-albedo" otherwise.
Rgb parse_classic_albedo(const std::string& text);

// The run's CPU time, estimated before any work from its photons and particles (docs/verify.md
// "Time"): 'typical' at the rates measured on the bundled defaults, 'least' at the fastest rates
// measured anywhere (the fiber bake's kMinSecondsPerPhoton; 0.8 M particles/s on a sparse sample,
// docs/PERFORMANCE.md), which is what a front end checks long work against.
struct VerifyEstimate {
  double typical = 0, least = 0;  // CPU seconds
  double photons = 0, particles = 0;
  unsigned cores = 1;  // the run's threads, or the machine's cores
  // The memory of the scene its ray traces fly through (fabric_scene_bytes of the sample's
  // counts), the largest of a run. A front end checks it (check_memory).
  double scene_bytes = 0;
  double fiber_segments = 0;  // the sample's (woven_sample_size), which its own cost grows with
};
// The rates of 'least', in words.
inline constexpr const char* kVerifyLeastRates =
    "0.5 us per photon and 1.25 us per particle per core at least";
// 'scene': what the woven sample itself costs (fabric_scene_seconds of its counts); the default
// is a small sample's.
VerifyEstimate estimate_verify(const VerifySettings& s, bool bake, bool fit, int fit_evaluations,
                               size_t fit_params, int fit_seeds,
                               const FabricSceneSeconds& scene = {});
VerifyEstimate estimate_verify(const VerifyPlan& plan);

// A sharded verify's job: the options that fix its result (a merge runs them again for the parts
// it does not hold), the content of its input files, and its units: the incident bins of every
// ray trace (verify_traces), trace after trace.
JobPart verify_job(const VerifyPlan& plan, Shard shard);
// The request a job's parts were made with (their options; the merge's output and threads).
VerifyRequest verify_job_request(const JobPart& job, const std::string& output);

// The classic baseline from a baked table (docs/verify.md "A baked fiber table"): roughness from
// the header; index from the spec the header names when a preset of that name has the header's
// spec hash, else cotton's; diffuse colour from 'albedo' when given, else the table's total albedo
// minus the classic Cook-Torrance lobe's. weft::Error naming 'file' when the header has no
// roughness or the colour is not a reflectance.
void classic_from_table(const std::string& file, const TabulatedBsdfTable& table,
                        const std::optional<Rgb>& albedo, const VerifySettings& s,
                        VerifyInputs& in);

}  // namespace weft
