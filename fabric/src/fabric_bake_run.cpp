// run_fabric_bake and merge_fabric_parts: a planned fabric bake's work, and the merge of a ray
// trace's parts (fabric_bake.h). They write the outputs and return their summaries; nothing
// printed.
#include <chrono>
#include <ctime>
#include <filesystem>

#include "weft/core/clock.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fabric/fabric_colour.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fabric/weave_tally.h"

namespace weft {
namespace {

std::vector<FiberOrientation> bake_orientations(const std::vector<Vec3>& tangents) {
  std::vector<FiberOrientation> out;
  for (const Vec3& t : tangents) out.push_back({t, 1.0});
  return out;
}

// The scene's memory and the weave tally's (weave_tally_bytes) against the budget, once the
// fiber table's channels are known; the tally's bytes (0 without it).
double check_weave_memory(const RunLimits& limits, const FabricRaytraceOptions& r, int channels,
                          double scene_bytes) {
  if (r.weave_positions_u == 0) return 0;
  const double bytes = weave_tally_bytes(r.resolution, r.weave_resolution, r.weave_positions_u,
                                         r.weave_positions_v, channels);
  check_memory(limits, scene_bytes + bytes, "", "--weave-positions",
               "the scene and the weave tally of " + std::to_string(r.weave_positions_u) + "x" +
                   std::to_string(r.weave_positions_v) + " positions at resolution " +
                   std::to_string(r.weave_resolution) + " (" + format_bytes(bytes) + ")");
  return bytes;
}

// What the summary says of the weave table.
nlohmann::json weave_summary(const FabricRaytraceResult& res, const std::string& file) {
  return {{"file", file},
          {"positions",
           std::to_string(res.weave.positions_u) + "x" + std::to_string(res.weave.positions_v)},
          {"resolution", res.weave.resolution},
          {"relative_noise", res.weave_relative_noise}};
}

// The files a part records beside its identity (kPartInputFilesKey): the fiber tables or spec
// files (a preset is no file) and the draft the weave options name.
std::vector<std::filesystem::path> recorded_fabric_inputs(const FabricBakePlan& p) {
  std::vector<std::filesystem::path> files;
  for (const auto& f : {p.fibers.fiber, p.fibers.warp_fiber, p.fibers.weft_fiber, p.fibers.draft}) {
    std::error_code ec;
    if (!f.empty() && std::filesystem::is_regular_file(f, ec)) files.emplace_back(f);
  }
  return files;
}

// The ray trace's table: whole, or in pieces with a shard or resume. False when the run ends
// without a table ('out' cancelled, or a shard's part written). Its summary keys go to 'extra',
// and the noise per channel of a run whole in this process to 'noise'.
bool trace_fabric(const FabricBakePlan& p, const WovenSample& sample, const FabricFibers& fibers,
                  double weave_bytes, const FabricBakeHooks& hooks, FabricBakeResult& out,
                  nlohmann::json& extra, std::vector<double>& noise) {
  const FabricBakeRequest& o = p.request;
  const FabricRaytraceOptions& r = p.raytrace;
  FabricRaytraceResult res;
  if (!o.shard.empty() || o.resume) {
    // The files the woven sample was made from (the fiber table is in the job by checksum).
    std::vector<std::filesystem::path> inputs;
    for (const auto& f : {o.weave, o.wif})
      if (!f.empty()) inputs.emplace_back(f);
    FabricPiecesOutcome pieces = raytrace_fabric_in_pieces(
        sample, input_file_hashes(inputs), fibers.map, r, o.output, o.shard, o.resume,
        hooks.progress, hooks.warning, input_file_hashes(recorded_fabric_inputs(p)));
    out.cancelled = pieces.cancelled;
    if (pieces.part_written) {
      out.part_units = pieces.units;
      out.shard = pieces.shard;
      if (!o.weave_out.empty())
        out.notes.push_back("the part carries the weave tally; `weft merge --weave-out " +
                            o.weave_out + "` writes the weave table");
    }
    if (!pieces.result) return false;
    res = std::move(*pieces.result);
  } else {
    res = fibers.map.tables.size() == 1
              ? raytrace_fabric_table(sample, fibers.first(), r, hooks.progress)
              : raytrace_fabric_table(sample, fibers.map, r, hooks.progress);
  }
  if (res.cancelled) {
    out.cancelled = true;
    return false;
  }
  out.table = res.table;
  record_particle_counts(out.table, res.splits, res.roulette_kills);
  extra = raytrace_summary(res);
  if (!o.resume) noise = res.relative_noise_per_channel;
  if (fibers.map.tables.size() > 1) extra["fiber_tables"] = fibers.summary();
  extra["estimator"] =
      r.next_event_rays > 0 ? "nee" : name_of(kChannelSamplingNames, r.channel_sampling);
  extra["next_event_rays"] = r.next_event_rays;
  extra["launch_lattice"] = r.launch_lattice;
  extra["straight_through"] = name_of(kStraightThroughNames, r.straight_through);
  extra["split_threshold"] = r.channel_sampling == ChannelSampling::mean
                                 ? nlohmann::json(nullptr)
                                 : nlohmann::json(r.split_threshold);
  if (!o.weave_out.empty()) {
    extra["weave"] = weave_summary(res, o.weave_out);
    extra["weave"]["memory_estimate_bytes"] = weave_bytes;
    out.weave = std::move(res.weave);
  }
  return true;
}

}  // namespace

std::optional<TabulatedBsdfTable> summed_fabric_table(const FabricBakePlan& p,
                                                      const WovenSample& sample,
                                                      const TabulatedBsdfTable& fiber,
                                                      const ProgressCallback& progress) {
  const FabricBakeRequest& o = p.request;
  FabricSummationOptions s;
  s.method =
      p.method == FabricMethod::kSummation ? FabricSummation::kPaper : FabricSummation::kVisible;
  s.resolution = o.resolution;
  if (o.samples) s.samples_per_cell = static_cast<int>(*o.samples);  // checked in the plan
  s.seed = o.seed;
  s.threads = o.threads;
  if (s.method == FabricSummation::kVisible) {
    // One scene for both sides, polled (at 5e7 triangles its build takes tens of seconds).
    std::optional<VisibleFiberTangents> seen = visible_fiber_tangents(sample, progress);
    if (!seen) return std::nullopt;
    s.top = bake_orientations(seen->top);
    s.bottom = bake_orientations(seen->bottom);
  }
  // The table stops with an error when its callback says stop (from_function): a stop of ours.
  bool stopped = false;
  const ProgressCallback asked = [&](const ProgressUpdate& u) {
    stopped = stopped || !progress(u);
    return !stopped;
  };
  try {
    return sum_fabric_table(fiber, s, asked);
  } catch (const Error&) {
    if (stopped) return std::nullopt;
    throw;
  }
}

FabricBakeResult run_fabric_bake(const FabricBakePlan& p, const FabricBakeHooks& hooks) {
  const FabricBakeRequest& o = p.request;
  FabricBakeResult out;
  const WovenSample sample = make_woven_sample(p.weave, hooks.progress);
  if (sample.cancelled) {
    out.cancelled = true;
    return out;
  }
  std::optional<FabricColourMatch> colour;
  FabricFiberOptions fiber_options = p.fibers;
  nlohmann::json thread_matches;
  if (p.fibers.thread_colours && p.fibers.thread_colour_method == ThreadColourMethod::kMatch) {
    std::optional<std::vector<FiberSpec>> specs =
        match_thread_colours(p, sample, hooks.progress, thread_matches);
    if (!specs) {
      out.cancelled = true;
      return out;
    }
    fiber_options.thread_specs = std::move(*specs);
  }
  if (p.colour) {
    colour = match_fabric_colour(p, sample, hooks.progress);
    if (colour->match.cancelled) {
      out.cancelled = true;
      return out;
    }
    // Spectral: a dyed fibre's saturated colour has no RGB table (its linear sRGB leaves the
    // gamut, a channel's albedo above 1).
    fiber_options.fiber_table = std::make_shared<const TabulatedBsdfTable>(
        colour_fiber_table(p, colour->match.spec, hooks.progress));
  }
  const FabricFibers fibers = load_fabric_fibers(fiber_options, sample, hooks.progress);
  const double weave_bytes =
      check_weave_memory(o.limits, p.raytrace, fibers.first().channels, p.scene_bytes);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();  // the process's CPU time, all threads
  nlohmann::json extra;
  std::vector<double> noise_per_channel;  // of a ray trace run whole in this process
  if (p.method == FabricMethod::kRaytrace) {
    if (!trace_fabric(p, sample, fibers, weave_bytes, hooks, out, extra, noise_per_channel))
      return out;
  } else {
    std::optional<TabulatedBsdfTable> summed =
        summed_fabric_table(p, sample, fibers.first(), hooks.progress);
    if (!summed) {
      out.cancelled = true;
      return out;
    }
    out.table = std::move(*summed);
  }
  const double seconds = seconds_since(t0);
  TabulatedBsdfTable& table = out.table;
  table.metadata["sample"] = sample.summary.source + " (" + sample.summary.detail + ")";
  table.metadata["program_version"] =
      std::string("weft ") + WEFT_VERSION + (o.front_end.empty() ? "" : " (" + o.front_end + ")");
  if (!p.note.empty()) table.metadata["note"] = p.note;
  if (colour) describe_colour_match(*colour, table, out);
  if (!o.output.empty()) table.write_exr(o.output);
  if (out.weave) {  // written after the fabric table, its metadata the table's as written
    describe_weave(table, *out.weave);
    out.weave->write_exr(o.weave_out);
  }
  const double cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  nlohmann::json& j = out.summary;
  j = {{"output", o.output},
       {"method", o.method},
       {"seconds", seconds},
       {"cpu_seconds", cpu_seconds}};
  j.update(fabric_table_summary(table));
  if (extra.is_object()) j.update(extra);
  // A resumed run's CPU time is of its last part only: its cost of 1 % would be too low.
  if (!noise_per_channel.empty())
    j["noise_cost"] =
        noise_cost_summary(noise_per_channel, p.raytrace.particles_per_bin, cpu_seconds);
  if (!p.note.empty()) j["notes"] = {p.note};
  if (colour) j["colour_match"] = colour_summary(*colour, table);
  if (!thread_matches.is_null()) j["thread_colour_match"] = thread_matches;
  if (p.scene_bytes > 0) j["scene_memory_estimate_bytes"] = p.scene_bytes;
  return out;
}

nlohmann::json merge_fabric_parts(const JobPart& all, const std::string& output,
                                  const std::string& weave_out) {
  const bool weave = all.job.contains("weave_positions");
  if (weave && weave_out.empty())
    throw Error("", "--weave-out",
                "the parts carry a weave tally (bake fabric --weave-out): give --weave-out "
                "FILE.exr for its table");
  if (!weave && !weave_out.empty())
    throw Error(weave_out, "--weave-out",
                "the parts carry no weave tally: bake them with --weave-out to have one");
  if (weave && std::filesystem::path(weave_out).extension() != ".exr")
    throw Error(weave_out, "--weave-out", "the weave table must be written to a .exr file");
  FabricRaytraceResult r = assemble_fabric_job(all);
  TabulatedBsdfTable& t = r.table;
  t.metadata["sample"] = ParamReader(all.job, "", "job").string("sample");
  t.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;  // as a bake writes
  t.write_exr(output);
  nlohmann::json j = {{"output", output}, {"method", "raytrace"}, {"parts_merged", true}};
  j.update(fabric_table_summary(t));
  j.update(raytrace_summary(r));
  if (weave) {
    describe_weave(t, r.weave);
    r.weave.write_exr(weave_out);
    j["weave"] = weave_summary(r, weave_out);
  }
  return j;
}

}  // namespace weft
