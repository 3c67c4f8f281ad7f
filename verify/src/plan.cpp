// weft verify's plan: the request's inputs read and checked, the time estimate, the sharded job's
// identity, and the classic baseline of a baked fiber table (plan.h).
#include "weft/verify/plan.h"

#include <algorithm>
#include <limits>
#include <sstream>

#include "weft/core/direction_grid.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/materials/colour_reading.h"
#include "weft/materials/cook_torrance.h"

namespace weft {

namespace {

// A baked fiber table (--fiber TABLE): read and validated (read_exr names the file and the field at
// fault), and of kind "fiber".
TabulatedBsdfTable read_fiber_table(const std::string& file) {
  TabulatedBsdfTable t;
  try {
    t = TabulatedBsdfTable::read_exr(file);
  } catch (const Error& e) {
    throw Error("", "--fiber", std::string("not a usable fiber table: ") + e.what());
  }
  if (t.kind != "fiber")
    throw Error(file, "--fiber",
                "holds a " + t.kind + " table; verify needs a fiber table (weft bake fiber)");
  return t;
}

// The woven sample: the options file's, with the pattern or draft given over it, at fiber detail
// (the fiber-level reference).
WeaveOptions plan_weave(const VerifyRequest& o) {
  if (!o.pattern.empty() && !o.wif.empty())
    throw Error("", "--wif", "give either --pattern or --wif, not both");
  WeaveOptions given;
  if (!o.pattern.empty()) given.pattern = o.pattern;
  if (!o.wif.empty()) given.wif = o.wif;
  given.detail = "fiber";
  const WeaveOptions base = o.weave.empty() ? WeaveOptions{} : read_weave_options(o.weave);
  return overlay(base, given);
}

// The fit's options, checked with the spec before any work; without the fit, none may be given.
void plan_fit(const VerifyRequest& o, VerifyPlan& p) {
  if (o.fit) {
    if (!o.shard.empty()) throw Error("", "--fit", "runs in one process, not with --shard");
    p.fit_names = parse_spec_fit_names(o.fit_params);
    p.fit_inner = parse_fit_inner(o.fit_inner);
    p.fit_options.method = parse_fit_method(o.fit_method);
    p.fit_options.max_evaluations = o.fit_evaluations;
    if (o.fit_seeds < 1 || o.fit_seeds > kMaxFitSeeds)
      throw Error("", "--fit-seeds",
                  std::to_string(o.fit_seeds) + " is outside 1 to " + std::to_string(kMaxFitSeeds));
    p.fit_seeds = o.fit_seeds;
    p.fit_options.validate(4);                       // the classic model always fits four
    (void)spec_fit_parameters(p.spec, p.fit_names);  // a spec without particles is refused here
    // A dye's own concentration moves the hue: fitted only where the colour can be judged.
    for (const auto& name : p.fit_names)
      if (name.rfind("dye", 0) == 0 && name != "dye_scale" &&
          !absolute_comparable(p.measured.colour_space))
        throw Error(p.measured_path.string(), "--fit-params",
                    "'" + name +
                        "' fits a dye's concentration, which moves the colour; the "
                        "measurement's colour space is " +
                        colour_space_name(p.measured.colour_space) +
                        ", not the tables' (linear sRGB), so its colour cannot judge it (give "
                        "--colour-space srgb if the measurement is sRGB)");
  } else if (o.fit_params_given || o.fit_evaluations_given || o.fit_inner_given ||
             o.fit_method_given || o.fit_seeds_given) {
    throw Error("",
                o.fit_params_given        ? "--fit-params"
                : o.fit_evaluations_given ? "--fit-evaluations"
                : o.fit_inner_given       ? "--fit-inner"
                : o.fit_method_given      ? "--fit-method"
                                          : "--fit-seeds",
                "only with --fit");
  }
}

// --colour or --colour-from, checked: the target, or none.
std::optional<ColourTarget> plan_verify_colour(const VerifyRequest& o, const VerifyPlan& p) {
  if (o.colour.empty() && o.colour_from.empty()) return std::nullopt;
  const std::string option = o.colour.empty() ? "--colour-from" : "--colour";
  if (!o.colour.empty() && !o.colour_from.empty())
    throw Error("", "--colour-from", "give --colour or --colour-from, not both");
  if (!o.colour_from.empty() && o.colour_from != "measured")
    throw Error("", "--colour-from", "must be 'measured', got '" + o.colour_from + "'");
  if (p.fiber_table)
    throw Error(
        o.fiber, option,
        "sets the depth of a fiber spec's dyes; a baked fiber table's colour is fixed: give "
        "the spec or preset it was baked from");
  if (o.fit) throw Error("", option, "the fit sets the colour itself: give one or the other");
  if (p.shard)
    throw Error("", option,
                "a sharded run would solve the colour in every shard: solve it once with `weft "
                "bake fabric --colour` and verify its dyed spec");
  if (!o.colour.empty()) return read_colour_target(o.colour, "--colour");
  const std::filesystem::path net = p.measured_path.parent_path() / "nbrdf_weights.txt";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(net, ec))
    throw Error(p.measured_path.string(), "--colour-from",
                "the measurement has no neural fit beside it (nbrdf_weights.txt): its d/8 reading "
                "needs the whole BRDF; give its colour with --colour");
  return linear_srgb_target(nbrdf_d8_reflectance(NbrdfNetwork::load(net)),
                            "measured:" + p.measured_path.parent_path().filename().string());
}

}  // namespace

VerifyPlan plan_verify(const VerifyRequest& o) {
  VerifyPlan p;
  p.request = o;
  const VerifyQuality q = parse_verify_quality(o.quality);
  p.settings = verify_settings(q);
  p.settings.seed = o.seed;
  p.settings.threads = o.threads;
  p.measured_path =
      o.measured.empty() ? bundled_measured_inplane() : std::filesystem::path(o.measured);
  p.measured = read_measured_inplane(p.measured_path);
  if (!o.colour_space.empty())
    p.measured.colour_space = parse_colour_space(o.colour_space, "", "--colour-space");
  // The fiber names a spec or preset, or (.exr) a baked fiber table, whose resolution the run
  // takes.
  if (std::filesystem::path(o.fiber).extension() == ".exr") {
    p.fiber_table = read_fiber_table(o.fiber);
    if (o.fit)
      throw Error(o.fiber, "--fit",
                  "the fit changes the fiber spec's parameters, and a baked table has no spec: "
                  "give a spec or preset");
    p.settings.resolution = p.fiber_table->resolution;
  } else {
    p.spec = load_fiber_spec(o.fiber);
  }
  if (!o.classic_albedo.empty()) p.classic_albedo = parse_classic_albedo(o.classic_albedo);
  p.weave = plan_weave(o);
  // A nonwoven mat is made of the fiber itself: its radius and density, unless the options give
  // them (a woven sample keeps its own fiber radius, as before).
  if (p.weave.pattern == kNonwovenPattern && !p.fiber_table) {
    if (!p.weave.fiber_radius_um) p.weave.fiber_radius_um = p.spec.fiber_radius_um;
    if (!p.weave.fiber_density_g_cm3 && p.spec.density_g_cm3 > 0)
      p.weave.fiber_density_g_cm3 = p.spec.density_g_cm3;
  }
  // The sample's pattern, draft and sizes checked now, not when the run comes to make it (a
  // suite's later fabric after the earlier ones' work).
  (void)woven_sample_size(p.weave);
  plan_fit(o, p);
  if (!o.shard.empty()) p.shard = parse_shard(o.shard, "--shard");
  p.colour = plan_verify_colour(o, p);
  return p;
}

Rgb parse_classic_albedo(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    const auto x = finite_number(part);
    if (!x || *x < 0 || *x > 1)
      throw Error("", "--classic-albedo",
                  "'" + text + "' is not three reflectances R,G,B in [0, 1] (linear sRGB)");
    v.push_back(*x);
  }
  if (v.size() != 3)
    throw Error("", "--classic-albedo",
                "'" + text + "' is not three reflectances R,G,B in [0, 1] (linear sRGB)");
  return {v[0], v[1], v[2]};
}

// ---- The time ------------------------------------------------------------------------------

namespace {

// Measured (docs/verify.md "Time"): red-cotton's full bake at the bake's defaults (next-event
// estimation and 4 surface samples), 8.6 s of CPU for 50 000 photons in each of 33 bands on 2
// threads (2026-12-06, `weft bake fiber red-cotton --bands spectral`), so 5.2 us per photon; the
// bundled poplin's fiber-level ray traces at default quality (docs/PERFORMANCE.md "Profile of
// `weft verify`", 2026-12-06, 2 idle cores): the computed model's 19.3 s wall for 2.05 M
// particles, so 19 us per particle of CPU, the classic model's 4.4 s for 1.02 M, 9 us; the plots
// and the rest, 7 s of CPU (tools/plot_verify.py --jobs 2 on a default run's nine incidences,
// 5.2 s, and the previews) whatever the quality.
constexpr double kTypicalSecondsPerPhoton = 5.2e-6;
constexpr double kTypicalSecondsPerParticle = 19e-6;
constexpr double kTypicalSecondsPerClassicParticle = 9e-6;
constexpr double kTypicalFixedSeconds = 7;
// The fiber-level renders (docs/PERFORMANCE.md "Profile of `weft verify`"): the renders stage of
// `weft verify --quality default --threads 2` took 5.1 s on 2 idle cores, about 10 s of CPU, for
// the four images at 8 spp, 2.1 M samples of square films (2026-12-06), so 5 us per image sample;
// counted on a square film of weave_render_size (an upper bound: the film is whole repeats, one
// side shorter), the patches' renders included. A model's reflection and transmission images are
// one pass (light groups): two scene builds.
constexpr double kTypicalSecondsPerWeaveSample = 5e-6;
constexpr int kWeaveImages = 4;  // computed and classic, reflection and transmission
constexpr int kWeavePasses = 2;  // computed and classic
constexpr double kLeastSecondsPerParticle = 1.25e-6;
// The fit (docs/verify.md "Fitting"): its inner bake (RGB, absorption as a weight, so no roulette)
// took 0.51 s of CPU for its 165 000 photons (5 000 in each of the 33 bands) on red-cotton near the
// fitted point (2026-12-03), 3.1 us per photon; its ray traces are one per search stage and model
// (the evaluations re-weight the stage's recorded paths, recorded_paths.h), typically 4 stages; an
// evaluation's re-weighting, curves and classic table about 0.04 s.
constexpr double kTypicalSecondsPerInnerPhoton = 3.1e-6;
constexpr double kTypicalFitStages = 4;
constexpr double kTypicalSecondsPerFitEvaluation = 0.04;
// The bundled acrylic felt's ray traces against the poplin's of the same fibre at draft quality
// (the bundled suite, 2026-12-06, metrics.json seconds.raytrace_computed): white 241 s against
// 37-48, pink 166-188 against 35; light walks long in a mat of 1 845 fibres.
constexpr double kNonwovenRayFactor = 5;
// A colour match's readings (--colour, --colour-from): 4 to 8 of at most 8 in the figures of
// docs/colour.md.
constexpr double kTypicalColourReadings = 6;
// The classic inner fiber table's Cook-Torrance samples (0.026 s of CPU for R = 6 at 4 per cell
// pair, docs/verify.md "The fit's time and the inner model's noise").
constexpr double kTypicalSecondsPerClassicSample = 1.25e-6;

}  // namespace

VerifyEstimate estimate_verify(const VerifySettings& s, bool bake, bool fit, int fit_evaluations,
                               size_t fit_params, int fit_seeds, const FabricSceneSeconds& scene) {
  VerifyEstimate e;
  e.cores = static_cast<unsigned>(thread_count(s.threads));
  const double bins = 2.0 * s.resolution * s.resolution;
  const double run_photons = bake ? double(s.fiber_photons_per_band) * kNumBands : 0.0;
  // Computed and classic, each 'particles_per_bin' per incident bin over all batches (a classic
  // particle costs less: its paths are shorter).
  const double computed_particles = double(s.particles_per_bin) * bins,
               classic_particles = computed_particles;
  const double run_particles = computed_particles + classic_particles;
  e.photons = run_photons;
  e.particles = run_particles;
  double fit_seconds = 0, fit_traces = 0;
  if (fit) {
    const FitInnerSettings inner = fit_inner_settings(s);
    const double inner_bins = 2.0 * inner.resolution * inner.resolution;
    // Per model and seed: the search, the optimum again and the Jacobian (2 per parameter; the
    // classic model has 4); then each seed's optimum at every seed, each a whole ray trace.
    const double seeds = fit_seeds, judged = seeds * seeds;
    const double computed_evals = seeds * (fit_evaluations + 1 + 2.0 * double(fit_params)) + judged;
    const double classic_evals = seeds * (fit_evaluations + 1 + 8.0) + judged;
    const double inner_photons = computed_evals * double(inner.fiber_photons_per_band) * kNumBands;
    fit_traces = 2 * (seeds * kTypicalFitStages + judged);
    const double inner_particles = fit_traces * double(inner.particles_per_bin) * inner_bins;
    e.photons += inner_photons + run_photons;
    e.particles += inner_particles + run_particles;
    const double classic_samples =
        classic_evals * double(inner.classic_samples) * inner_bins * inner_bins;
    fit_seconds = inner_photons * kTypicalSecondsPerInnerPhoton +
                  inner_particles * kTypicalSecondsPerParticle * scene.per_ray_factor +
                  classic_samples * kTypicalSecondsPerClassicSample +
                  (computed_evals + classic_evals) * kTypicalSecondsPerFitEvaluation;
  }
  const double weave_samples =
      double(kWeaveImages) * s.weave_render_size * s.weave_render_size * s.weave_render_spp;
  // The run's (with the fit: twice, the fitted models at the run's quality) and the fit's.
  const double runs = fit ? 2 : 1;
  // The sample's own cost (fabric_scene_seconds): made once, its scene built for every ray trace
  // (computed and classic, each batch) and every fiber-level render, every ray slower in a larger
  // scene.
  const double run_traces = 2.0 * s.batches + kWeavePasses;
  e.typical = runs * (run_photons * kTypicalSecondsPerPhoton +
                      (computed_particles * kTypicalSecondsPerParticle +
                       classic_particles * kTypicalSecondsPerClassicParticle) *
                          scene.per_ray_factor) +
              fit_seconds + weave_samples * kTypicalSecondsPerWeaveSample * scene.per_ray_factor +
              kTypicalFixedSeconds + scene.make + (runs * run_traces + fit_traces) * scene.build;
  e.least = e.photons * kMinSecondsPerPhoton + e.particles * kLeastSecondsPerParticle;
  return e;
}

VerifyEstimate estimate_verify(const VerifyPlan& p) {
  // A nonwoven mat is small (nonwoven.h), but light walks long in it: its rays cost the
  // poplin's times kNonwovenRayFactor. Its making is counted from its placement work.
  const WovenSampleSize z = woven_sample_size(p.weave);
  FabricSceneSeconds scene = fabric_scene_seconds(z);
  if (p.weave.pattern == kNonwovenPattern) scene.per_ray_factor = kNonwovenRayFactor;
  VerifyEstimate e =
      estimate_verify(p.settings, !p.fiber_table, p.request.fit, p.fit_options.max_evaluations,
                      p.fit_names.size(), p.fit_seeds, scene);
  if (p.colour) {
    // The colour match's readings (whole_run.cpp verify_colour_match): each a spectral fiber bake
    // at the run's photons and the normal's incident bin at the first batch's particles; typically
    // 4 to 8 of the at most kFabricColourReadings (docs/colour.md), so the typical count is 6 and
    // the least 2 (the recipe and the undyed fibre).
    const VerifySettings& s = p.settings;
    const double photons = double(s.fiber_photons_per_band) * kNumBands;
    const double particles = double(s.particles_per_bin) / double(s.batches);
    const double reading = photons * kTypicalSecondsPerPhoton +
                           particles * kTypicalSecondsPerParticle * scene.per_ray_factor +
                           scene.build;
    e.typical += kTypicalColourReadings * reading;
    e.least += 2 * (photons * kMinSecondsPerPhoton + particles * kLeastSecondsPerParticle);
  }
  e.scene_bytes = fabric_scene_bytes(z);
  // The segments the sample will hold (its memory's count, not the packing's estimate).
  e.fiber_segments = z.made_curve_segments > 0 ? z.made_curve_segments : z.curve_segments;
  return e;
}

// ---- The sharded job -------------------------------------------------------------------------

JobPart verify_job(const VerifyPlan& p, Shard shard) {
  const VerifyRequest& o = p.request;
  std::vector<std::filesystem::path> files{p.measured_path};
  std::error_code ec;
  for (const std::string& f : {o.weave, o.wif, o.fiber})
    if (!f.empty() && std::filesystem::is_regular_file(f, ec)) files.emplace_back(f);
  JobPart job;
  job.command = "verify";
  job.job = {{"options",
              {{"fiber", o.fiber},
               {"measured", o.measured},
               {"colour_space", o.colour_space},
               {"weave", o.weave},
               {"pattern", o.pattern},
               {"wif", o.wif},
               {"quality", o.quality},
               {"seed", o.seed}}},
             {"inputs", input_file_hashes(files)},
             {"spec_hash", p.fiber_table ? p.fiber_table->checksum() : fiber_spec_hash_hex(p.spec)},
             {"program_version", WEFT_VERSION}};
  job.units_total = verify_traces(p.settings).size() * DirectionGrid{p.settings.resolution}.bins();
  job.shard = shard;
  job.extra = {{"threads", o.threads}};  // reported in metrics.json; results do not depend on it
  return job;
}

VerifyRequest verify_job_request(const JobPart& all, const std::string& output) {
  VerifyRequest o;
  // Parts are a user's files: every option is read through the reader, which names the field
  // (job.options.fiber, ...) when it is missing or of the wrong type, and checks the numbers
  // before they are converted.
  ParamReader opt = ParamReader(all.job, "", "job").object("options");
  o.fiber = opt.string_or_empty("fiber");
  o.measured = opt.string_or_empty("measured");
  o.colour_space = opt.has("colour_space") ? opt.string_or_empty("colour_space") : "";
  o.weave = opt.string_or_empty("weave");
  o.pattern = opt.string_or_empty("pattern");
  o.wif = opt.string_or_empty("wif");
  o.quality = opt.string_or_empty("quality");
  o.seed = opt.count("seed", 0, std::numeric_limits<uint64_t>::max());
  o.threads =
      static_cast<int>(ParamReader(all.extra, "", "extra").integer("threads", 0, 0, 1 << 16));
  o.output = output;
  return o;
}

// ---- The classic baseline of a baked table ----------------------------------------------------

namespace {

// The classic fiber's index: the header's preset's at 550 nm when the preset has the header's
// spec hash, else cotton's; and where it came from, for the report.
std::pair<double, std::string> classic_ior_of(const TabulatedBsdfTable& t) {
  std::pair<double, std::string> ior = {
      kCottonIor, "cotton's index " + std::to_string(kCottonIor).substr(0, 5) +
                      " (the header names no preset with its spec hash)"};
  const auto name = t.metadata.find("spec_name"), hash = t.metadata.find("spec_hash");
  if (name == t.metadata.end() || hash == t.metadata.end()) return ior;
  const auto presets = fiber_preset_names();
  if (std::find(presets.begin(), presets.end(), name->second) == presets.end()) return ior;
  const FiberSpec spec = parse_fiber_spec(fiber_preset_json(name->second), name->second);
  if (fiber_spec_hash_hex(spec) == hash->second)
    ior = {spec.host_n[kNumBands / 2],  // 550 nm
           "the index at 550 nm of preset " + name->second + " (the header's spec name and hash)"};
  return ior;
}

}  // namespace

// How far outside [0, 1] a band of the table's classic diffuse colour may lie by noise alone.
constexpr double kClassicBandNoise = 1e-3;

void classic_from_table(const std::string& file, const TabulatedBsdfTable& t,
                        const std::optional<Rgb>& albedo, const VerifySettings& s,
                        VerifyInputs& in) {
  const auto rough = fiber_table_roughness(t, file);
  if (!rough)
    throw Error(file, "roughness",
                "the table's header does not state the fiber's surface roughness (weft bake "
                "fiber writes it), which the classic baseline needs: bake the table with weft "
                "bake fiber, or give a fiber spec or preset");
  in.classic_distribution = *rough;
  const auto [ior, ior_source] = classic_ior_of(t);
  in.classic_ior = ior;
  if (albedo) {
    in.classic_diffuse = albedo;
    in.classic_source = "--classic-albedo; the table header's roughness; " + ior_source;
    return;
  }
  const std::vector<double> diffuse =
      classic_diffuse_from_fiber_table(t, *rough, in.classic_ior, s.seed, s.threads);
  // As a reflectance of the light that gets past the lobe (classic.h), checked where it is a
  // reflectance: per band for a spectral table (its linear sRGB may leave the gamut for a
  // saturated dye; verify_classic_fiber brings that to the classic model's RGB and reports it),
  // per channel for an RGB one.
  const double entering = classic_entering_fraction(*rough, in.classic_ior);
  for (size_t k = 0; k < diffuse.size(); ++k) {
    // A band is a Monte Carlo difference (total albedo minus the lobe's), so a band the dye
    // leaves alone may exceed 1 by its noise (1.00003 at 710 nm on red-cotton at default photons);
    // verify_classic_fiber clips and reports that, as it does the gamut.
    // An RGB table's channels become the classic colour as they are, so they stay in [0, 1].
    const double v = diffuse[k] / entering;
    const double noise = t.channels == kNumBands ? kClassicBandNoise : 0.0;
    if (!(v >= -noise && v <= 1 + noise))
      throw Error(file, "--classic-albedo",
                  "the classic baseline's diffuse colour from the table (its total albedo minus "
                  "the Cook-Torrance lobe's, over what the lobe leaves) is " +
                      std::to_string(v) + " in " +
                      (t.channels == kNumBands ? "band " + std::to_string(k)
                                               : std::string("channel ") + "RGB"[k]) +
                      ", not a reflectance in [0, 1]: give --classic-albedo R,G,B");
  }
  if (t.channels == kNumBands)
    for (int b = 0; b < kNumBands; ++b) in.volume_albedo[b] = diffuse[b];
  else
    in.classic_diffuse = Rgb(diffuse[0] / entering, diffuse[1] / entering, diffuse[2] / entering);
  in.classic_source =
      "the fiber table: its total albedo minus the classic Cook-Torrance lobe's, over what the "
      "lobe leaves, per " +
      std::string(t.channels == kNumBands ? "band" : "channel") +
      "; the table header's roughness; " + ior_source;
}

}  // namespace weft
