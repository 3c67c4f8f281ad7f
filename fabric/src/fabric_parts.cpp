// The ray-traced fabric table in pieces: a shard of its incident bins (`weft bake fabric --method
// raytrace --shard K/N`) written as a part, checkpoints of finished bins (`--resume`), and the
// merge of the parts. Each incident bin's row of the table depends only on (seed, bin): a piece
// holds the rows a whole run computes, bit for bit.
#include "weft/fabric/fabric_parts.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/weave_tally.h"

namespace weft {
namespace {

// The fibers in a job's identity: one table's checksum as ever, or per-yarn tables' checksums and
// maps ('f' distinct).
void describe_fibers(const FiberTables& f, nlohmann::json& job) {
  // The checksum covers the cells; a table that names a surface lobe is traced with the lobe exact
  // (fabric_raytrace.h), so its lobe is part of what the parts were traced with.
  for (size_t k = 0; k < f.tables.size(); ++k)
    if (f.tables[k]->surface_lobe)
      job["fiber_surface_lobes"][std::to_string(k)] = f.tables[k]->surface_lobe->attributes();
  if (f.tables.size() == 1) {
    job["fiber_checksum"] = f.tables[0]->checksum();
    return;
  }
  nlohmann::json sums = nlohmann::json::array();
  for (const TabulatedBsdfTable* t : f.tables) sums.push_back(t->checksum());
  job["fiber_tables"] = {
      {"checksums", sums}, {"of_yarn", f.table_of_yarn}, {"of_mesh", f.table_of_mesh}};
}

// The ray trace of 'fibers' (distinct): the single-table call for one.
FabricRaytraceResult trace(const WovenSample& sample, const FiberTables& fibers,
                           const FabricRaytraceOptions& r, const ProgressCallback& progress) {
  return fibers.tables.size() == 1 ? raytrace_fabric_table(sample, *fibers.tables[0], r, progress)
                                   : raytrace_fabric_table(sample, fibers, r, progress);
}

JobPart fabric_job(const FiberTables& fibers, const WovenSample& sample,
                   const nlohmann::json& inputs, const FabricRaytraceOptions& r, Shard shard) {
  JobPart p;
  p.command = "bake fabric";
  p.job = {{"method", "raytrace"},
           {"estimator_revision", kFabricRaytraceRevision},
           {"inputs", inputs},
           {"sample", sample.summary.source + " (" + sample.summary.detail + ")"},
           {"resolution", r.resolution},
           {"particles_per_bin", r.particles_per_bin},
           {"seed", r.seed},
           {"max_scatterings", r.max_scatterings},
           {"roulette_threshold", r.roulette_threshold},
           {"estimator", name_of(kChannelSamplingNames, r.channel_sampling)},
           {"split_threshold", r.split_threshold},
           {"max_copies_per_particle", r.max_copies_per_particle},
           {"program_version", WEFT_VERSION}};
  describe_fibers(fibers, p.job);
  // Only where on, so that the parts of runs before the option keep their identity.
  if (r.next_event_rays > 0) p.job["next_event_rays"] = r.next_event_rays;
  if (r.launch_lattice > 1) p.job["launch_lattice"] = r.launch_lattice;
  if (r.straight_through != StraightThrough::sampled)
    p.job["straight_through"] = name_of(kStraightThroughNames, r.straight_through);
  if (r.weave_positions_u > 0) {  // the parts carry the weave tally (weave_tally.h)
    p.job["weave_positions"] = {r.weave_positions_u, r.weave_positions_v};
    p.job["weave_resolution"] = r.weave_resolution;
  }
  p.units_total = static_cast<uint64_t>(DirectionGrid{r.resolution}.bins());
  p.shard = shard;
  return p;
}

// A bin's unit: its row of the table, then its books (FabricBinBooks: the power as doubles, the
// counts as raw 64-bit values, noise2 and signal2 per channel), then with the weave tally its
// weave_values and weave_noise2.
constexpr size_t kBookValues = 5 + 7;

// The weave a job's parts carry (positions 0: none): sizes from the job, the repeat from extra.
// Parts are a user's files: each value is checked as a job file's would be before it is used.
WeaveShape weave_shape_of(const JobPart& all) {
  WeaveShape w;
  if (!all.job.contains("weave_positions")) return w;
  ParamReader job(all.job, "", "job"), extra(all.extra, "", "extra");
  const auto p = job.counts("weave_positions", 2, 1, WeaveTable::kMaxPositions);
  w.resolution =
      static_cast<int>(job.count("weave_resolution", 1, TabulatedBsdfTable::kMaxResolution));
  if (p.size() != 2) throw Error("", "job.weave_positions", "expected the repeat's two counts");
  if (!extra.at("weave_repeat_m").is_array() || extra.at("weave_repeat_m").size() != 2)
    throw Error("", "extra.weave_repeat_m", "expected the repeat's two sizes");
  w.positions_u = static_cast<int>(p[0]), w.positions_v = static_cast<int>(p[1]);
  w.repeat_u_m =
      extra.check_number(extra.at("weave_repeat_m")[0], "extra.weave_repeat_m[0]", 1e-9, 1e3);
  w.repeat_v_m =
      extra.check_number(extra.at("weave_repeat_m")[1], "extra.weave_repeat_m[1]", 1e-9, 1e3);
  return w;
}

}  // namespace

void record_particle_counts(TabulatedBsdfTable& t, uint64_t splits, uint64_t roulette_kills) {
  t.metadata["splits"] = std::to_string(splits);
  t.metadata["roulette_kills"] = std::to_string(roulette_kills);
}

FabricRaytraceResult assemble_fabric_job(const JobPart& all) {
  ParamReader job(all.job, "", "job"), extra(all.extra, "", "extra");
  const auto resolution =
      static_cast<int>(job.count("resolution", 1, TabulatedBsdfTable::kMaxResolution));
  const auto channels = static_cast<int>(extra.count("channels", 1, kNumBands));
  FabricRaytraceResult r = assemble_fabric_bins(all.units, 0, all.units_total, resolution, channels,
                                                weave_shape_of(all));
  const nlohmann::json& metadata = extra.at("metadata");
  if (!metadata.is_object()) throw Error("", "extra.metadata", "must be an object of strings");
  for (const auto& [key, value] : metadata.items()) {
    if (!value.is_string()) throw Error("", "extra.metadata." + key, "must be a string");
    r.table.metadata[key] = value.get<std::string>();
  }
  record_particle_counts(r.table, r.splits, r.roulette_kills);
  if (r.weave.positions_u > 0) describe_weave(r.table, r.weave);
  return r;
}

void encode_fabric_bin(const FabricRaytraceResult& res, uint64_t a, std::vector<double>& v) {
  const size_t row = res.bin_books.size() * static_cast<size_t>(res.table.channels);
  v.assign(res.table.values.begin() + static_cast<std::ptrdiff_t>(a * row),
           res.table.values.begin() + static_cast<std::ptrdiff_t>((a + 1) * row));
  const FabricBinBooks& b = res.bin_books.at(a);
  for (double x : {b.launched, b.exited, b.absorbed, b.lost, b.roulette_net}) v.push_back(x);
  for (uint64_t x : {b.particles, b.scatterings, b.wraps, b.splits, b.inside_hits, b.roulette_kills,
                     b.tube_passes})
    push_u64(v, x);
  v.insert(v.end(), b.noise2.begin(), b.noise2.end());
  v.insert(v.end(), b.signal2.begin(), b.signal2.end());
  v.insert(v.end(), b.weave_values.begin(), b.weave_values.end());
  v.insert(v.end(), b.weave_noise2.begin(), b.weave_noise2.end());
}

int fabric_bin_channels(const std::vector<double>& unit, uint64_t bins) {
  const size_t n = unit.size();
  if (n < kBookValues || (n - kBookValues) % (bins + 2) != 0 || n == kBookValues)
    throw Error("", "units", "not the record of an incident bin of a ray-traced table");
  return static_cast<int>((n - kBookValues) / (bins + 2));
}

FabricRaytraceResult assemble_fabric_bins(const std::map<uint64_t, std::vector<double>>& units,
                                          uint64_t first_unit, uint64_t bins, int resolution,
                                          int channels, const WeaveShape& weave) {
  // The shape before anything is sized by it: the table's own limits, and one unit per bin.
  if (resolution < 1 || resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must lie in [1, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "]");
  if (channels != 3 && channels != kNumBands)
    throw Error("", "channels", "need 3 (RGB) or " + std::to_string(kNumBands) + " channels");
  if (bins != static_cast<uint64_t>(DirectionGrid{resolution}.bins()))
    throw Error("", "units_total",
                "not the bins of a table of resolution " + std::to_string(resolution));
  FabricRaytraceResult r;
  TabulatedBsdfTable& t = r.table;
  t.resolution = resolution;
  t.kind = "fabric";
  t.channels = channels;
  const size_t nc = static_cast<size_t>(channels), row = bins * nc;
  t.values.assign(bins * row, 0.0f);
  r.bin_books.resize(bins);
  for (uint64_t a = 0; a < bins; ++a) {
    const auto it = units.find(first_unit + a);
    if (it == units.end())
      throw Error("", "units", "incident bin " + std::to_string(a) + " is missing");
    const std::vector<double>& v = it->second;
    const size_t weave_values =
        weave.on() ? static_cast<size_t>(weave.positions()) *
                         static_cast<size_t>(DirectionGrid{weave.resolution}.bins()) * nc
                   : 0;
    const size_t books = row + kBookValues + 2 * nc;
    if (v.size() != books + (weave.on() ? weave_values + nc : 0))
      throw Error("", "units", "a bin's record of another size");
    for (size_t k = 0; k < row; ++k) t.values[a * row + k] = static_cast<float>(v[k]);
    FabricBinBooks& b = r.bin_books[a];
    const double* x = v.data() + row;
    b.launched = x[0], b.exited = x[1], b.absorbed = x[2], b.lost = x[3], b.roulette_net = x[4];
    b.particles = as_u64(x[5]), b.scatterings = as_u64(x[6]), b.wraps = as_u64(x[7]);
    b.splits = as_u64(x[8]), b.inside_hits = as_u64(x[9]);
    b.roulette_kills = as_u64(x[10]), b.tube_passes = as_u64(x[11]);
    b.noise2.assign(x + kBookValues, x + kBookValues + nc);
    b.signal2.assign(x + kBookValues + nc, x + kBookValues + 2 * nc);
    b.weave_values.assign(v.begin() + books, v.begin() + books + weave_values);
    if (weave.on()) b.weave_noise2.assign(v.begin() + books + weave_values, v.end());
  }
  t.validate("");
  fabric_raytrace_totals(r);
  weave_totals(weave, r);
  return r;
}

FabricPiecesOutcome raytrace_fabric_in_pieces(
    const WovenSample& sample, const nlohmann::json& inputs, const FiberTables& given,
    const FabricRaytraceOptions& r, const std::string& output, const std::string& shard_text,
    bool resume, const ProgressCallback& progress,
    const std::function<void(const std::string&)>& warning, const nlohmann::json& recorded_inputs) {
  FabricPiecesOutcome outcome;
  const Shard shard = shard_text.empty() ? Shard{} : parse_shard(shard_text, "--shard");
  if (given.tables.size() > 1) validate_fiber_tables(given, sample);
  const FiberTables fibers = given.tables.size() > 1 ? distinct_fiber_tables(given) : given;
  JobPart job = fabric_job(fibers, sample, inputs, r, shard);
  const UnitRange range = shard_units(job.units_total, shard);
  JobPart done = job;
  std::vector<std::string> warnings;
  if (const auto cp = load_checkpoint(output, job, resume, warnings)) done = *cp;
  for (const std::string& w : warnings) warning(w);
  done.checkpoint = true;
  // Pieces of about an eighth of the range between checkpoints; the whole range without them.
  const uint64_t step = resume ? std::max<uint64_t>(1, (range.last - range.first + 7) / 8)
                               : std::max<uint64_t>(1, range.last - range.first);
  for (uint64_t a = range.first; a < range.last;) {
    if (done.units.count(a)) {
      ++a;
      continue;
    }
    uint64_t b = a;
    while (b < range.last && b - a < step && !done.units.count(b)) ++b;
    FabricRaytraceOptions piece = r;
    piece.first_bin = static_cast<int>(a);
    piece.bin_count = static_cast<int>(b - a);
    const FabricRaytraceResult res = trace(sample, fibers, piece, progress);
    if (res.cancelled) {
      outcome.cancelled = true;
      return outcome;
    }
    for (uint64_t u = a; u < b; ++u) encode_fabric_bin(res, u, done.units[u]);
    done.extra = {{"channels", res.table.channels}, {"metadata", res.table.metadata}};
    if (r.weave_positions_u > 0)
      done.extra["weave_repeat_m"] = {res.weave.repeat_u_m, res.weave.repeat_v_m};
    if (resume) write_job_part(checkpoint_path(output), done);
    a = b;
  }
  if (done.extra.empty() || !done.extra.contains("metadata")) {
    // Every bin came from the checkpoint, or the shard has none: the metadata of an empty piece.
    FabricRaytraceOptions none = r;
    none.first_bin = 0;
    none.bin_count = 1;
    none.particles_per_bin = 1;
    const auto t = trace(sample, fibers, none, no_progress());
    auto md = t.table.metadata;
    md["particles_per_bin"] = std::to_string(r.particles_per_bin);
    done.extra = {{"channels", t.table.channels}, {"metadata", md}};
    if (r.weave_positions_u > 0)
      done.extra["weave_repeat_m"] = {t.weave.repeat_u_m, t.weave.repeat_v_m};
  }
  done.checkpoint = false;
  if (!shard.whole()) {
    if (!recorded_inputs.empty()) done.extra[kPartInputFilesKey] = recorded_inputs;
    write_job_part(output, done);
    std::filesystem::remove(checkpoint_path(output));
    outcome.part_written = true;
    outcome.units = range;
    outcome.shard = shard;
    return outcome;
  }
  std::filesystem::remove(checkpoint_path(output));
  outcome.result = assemble_fabric_job(done);
  return outcome;
}

nlohmann::json raytrace_summary(const FabricRaytraceResult& res) {
  return {{"particles", res.particles},
          {"scatterings", res.scatterings},
          {"splits", res.splits},
          {"roulette_kills", res.roulette_kills},
          {"exited", res.exited},
          {"absorbed", res.absorbed},
          {"lost", res.lost},
          {"roulette_net", res.roulette_net},
          {"relative_noise", res.relative_noise},
          {"relative_noise_per_channel", res.relative_noise_per_channel}};
}

nlohmann::json noise_cost_summary(const std::vector<double>& relative_noise_per_channel,
                                  uint64_t particles_per_bin, double cpu_seconds) {
  if (!(cpu_seconds > 0) || !std::isfinite(cpu_seconds))
    throw Error("", "cpu_seconds", "must be positive and finite to scale the noise's cost");
  if (particles_per_bin == 0)
    throw Error("", "particles_per_bin", "must be positive to scale the noise's cost");
  constexpr double kTarget = 0.01;
  nlohmann::json cpu = nlohmann::json::array(), particles = nlohmann::json::array();
  for (double noise : relative_noise_per_channel) {
    if (!(noise > 0) || !std::isfinite(noise)) {
      cpu.push_back(nullptr), particles.push_back(nullptr);
      continue;
    }
    const double scale = (noise / kTarget) * (noise / kTarget);
    cpu.push_back(cpu_seconds * scale);
    particles.push_back(std::ceil(static_cast<double>(particles_per_bin) * scale));
  }
  return {{"target_relative_noise", kTarget},
          {"cpu_seconds_to_target", cpu},
          {"particles_per_bin_to_target", particles}};
}

nlohmann::json fabric_table_summary(const TabulatedBsdfTable& table) {
  // Light arriving along the normal, where it goes; and what a view along the normal gathers
  // under uniform light (they differ for a non-reciprocal table, fabric_summation.h).
  const auto normal = table.directional_albedo(table.grid().bin_of({0, 0, 1}));
  const auto view = table.directional_albedo_seen_from(table.grid().bin_of({0, 0, 1}));
  return {{"resolution", table.resolution},
          {"sample", table.metadata.at("sample")},
          {"reflectance_normal_incidence", normal.reflectance},
          {"transmittance_normal_incidence", normal.transmittance},
          {"reflectance_normal_view", view.reflectance},
          {"transmittance_normal_view", view.transmittance}};
}

}  // namespace weft
