// The ray-traced fabric table in pieces: a shard of its incident bins (`weft bake fabric --method
// raytrace --shard K/N`) written as a part, checkpoints of finished bins (`--resume`), and the
// merge of the parts. Each incident bin's row of the table depends only on (seed, bin): a piece
// holds the rows a whole run computes, bit for bit.
#include "fabric_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "weft/core/error.h"

namespace weft::cli {
namespace {

JobPart fabric_job(const TabulatedBsdfTable& fiber, const WovenSample& sample,
                   const nlohmann::json& inputs, const FabricRaytraceOptions& r, Shard shard) {
  JobPart p;
  p.command = "bake fabric";
  p.job = {{"method", "raytrace"},
           {"inputs", inputs},
           {"fiber_checksum", fiber.checksum()},
           {"sample", sample.summary.source + " (" + sample.summary.detail + ")"},
           {"resolution", r.resolution},
           {"particles_per_bin", r.particles_per_bin},
           {"seed", r.seed},
           {"max_scatterings", r.max_scatterings},
           {"roulette_threshold", r.roulette_threshold},
           {"program_version", WEFT_VERSION}};
  p.units_total = static_cast<uint64_t>(DirectionGrid{r.resolution}.bins());
  p.shard = shard;
  return p;
}

// The table from the rows of every bin, with the metadata of the pieces.
TabulatedBsdfTable assemble(const JobPart& all, int resolution) {
  TabulatedBsdfTable t;
  t.resolution = resolution;
  t.kind = "fabric";
  t.channels = all.extra.at("channels").get<int>();
  t.metadata = all.extra.at("metadata").get<std::map<std::string, std::string>>();
  const size_t bins = all.units_total, row = bins * static_cast<size_t>(t.channels);
  t.values.assign(bins * row, 0.0f);
  for (const auto& [a, v] : all.units) {
    if (v.size() != row) throw Error("", "units", "a row of another size");
    for (size_t k = 0; k < row; ++k) t.values[a * row + k] = static_cast<float>(v[k]);
  }
  t.validate("");
  return t;
}

}  // namespace

std::optional<FabricRaytraceResult> raytrace_fabric_in_pieces(
    const WovenSample& sample, const nlohmann::json& inputs, const TabulatedBsdfTable& fiber,
    const FabricRaytraceOptions& r, const std::string& output, const std::string& shard_text,
    bool resume, const ProgressCallback& progress, int* exit_code) {
  *exit_code = 0;
  const Shard shard = shard_text.empty() ? Shard{} : parse_shard(shard_text, "--shard");
  JobPart job = fabric_job(fiber, sample, inputs, r, shard);
  const UnitRange range = shard_units(job.units_total, shard);
  const size_t row = job.units_total * static_cast<size_t>(fiber.channels);
  JobPart done = job;
  if (const auto cp = load_checkpoint(output, job, resume)) done = *cp;
  done.checkpoint = true;
  FabricRaytraceResult sum;
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
    const FabricRaytraceResult res = raytrace_fabric_table(sample, fiber, piece, progress);
    if (res.cancelled) {
      std::fprintf(stderr, "\nweft: bake cancelled; %s\n",
                   resume ? "--resume continues from the last checkpoint" : "nothing was written");
      *exit_code = 130;
      return std::nullopt;
    }
    for (uint64_t u = a; u < b; ++u)
      done.units[u].assign(res.table.values.begin() + static_cast<std::ptrdiff_t>(u * row),
                           res.table.values.begin() + static_cast<std::ptrdiff_t>((u + 1) * row));
    done.extra = {{"channels", res.table.channels}, {"metadata", res.table.metadata}};
    sum.particles += res.particles, sum.scatterings += res.scatterings, sum.wraps += res.wraps;
    if (resume) write_job_part(checkpoint_path(output), done);
    a = b;
  }
  if (done.extra.empty() || !done.extra.contains("metadata")) {
    // Every bin came from the checkpoint, or the shard has none: the metadata of an empty piece.
    FabricRaytraceOptions none = r;
    none.first_bin = 0;
    none.bin_count = 1;
    none.particles_per_bin = 1;
    const auto t = raytrace_fabric_table(sample, fiber, none, no_progress());
    auto md = t.table.metadata;
    md["particles_per_bin"] = std::to_string(r.particles_per_bin);
    done.extra = {{"channels", t.table.channels}, {"metadata", md}};
  }
  done.checkpoint = false;
  if (!shard.whole()) {
    write_job_part(output, done);
    std::filesystem::remove(checkpoint_path(output));
    std::printf("incident bins %llu..%llu (shard %u/%u) -> %s\n",
                static_cast<unsigned long long>(range.first),
                static_cast<unsigned long long>(range.last), shard.index, shard.count,
                output.c_str());
    return std::nullopt;
  }
  std::filesystem::remove(checkpoint_path(output));
  sum.table = assemble(done, r.resolution);
  // The energy books and the noise are sums over all bins at once: not kept across pieces.
  sum.exited = sum.absorbed = sum.lost = sum.roulette_net = sum.relative_noise = NAN;
  return sum;
}

int merge_fabric_bake(const JobPart& all, const std::string& output, bool json) {
  TabulatedBsdfTable t = assemble(all, all.job.at("resolution").get<int>());
  t.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;  // as bake fabric writes
  t.write_exr(output);
  if (json)
    std::cout << nlohmann::json({{"output", output}, {"parts_merged", true}}).dump(2) << "\n";
  else
    std::printf("%s: ray-traced fabric table, R = %d, merged\n", output.c_str(), t.resolution);
  return 0;
}

}  // namespace weft::cli
