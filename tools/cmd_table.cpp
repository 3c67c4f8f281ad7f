// weft table: inspect tabulated BSDF tables (info) and bake analytic materials into them (bake).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/params.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/registry.h"

namespace weft::cli {
namespace {

struct InfoOptions {
  std::string file;
  bool json = false;
};

int run_info(const InfoOptions& o) {
  const auto t = TabulatedBsdfTable::read_exr(o.file);
  float lo = t.values.front(), hi = lo;
  for (float v : t.values) lo = std::min(lo, v), hi = std::max(hi, v);
  const DirectionGrid g = t.grid();
  // Light arriving along the normal (w_i = n), summed over all exits.
  const auto normal = t.directional_albedo(g.bin_of({0, 0, 1}));
  // Seen along the normal under uniform light (the renderer's reading; differs from the above
  // for a non-reciprocal table, e.g. the paper's summed fabric tables).
  const auto view = t.directional_albedo_seen_from(g.bin_of({0, 0, 1}));
  std::vector<double> albedo(t.channels);
  for (int c = 0; c < t.channels; ++c) albedo[c] = normal.total(c);
  const nlohmann::json j = {{"file", o.file},
                            {"format_version", TabulatedBsdfTable::kFormatVersion},
                            {"resolution", t.resolution},
                            {"bins", g.bins()},
                            {"bands", t.bands()},
                            {"kind", t.kind},
                            {"metadata", t.metadata},
                            {"checksum", t.checksum()},
                            {"min_per_sr", lo},
                            {"max_per_sr", hi},
                            {"albedo_normal_incidence", albedo},
                            {"reflectance_normal_incidence", normal.reflectance},
                            {"transmittance_normal_incidence", normal.transmittance},
                            {"reflectance_normal_view", view.reflectance},
                            {"transmittance_normal_view", view.transmittance}};
  if (o.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    for (const auto& [k, v] : j.items()) std::cout << k << ": " << v.dump() << "\n";
  }
  return 0;
}

struct BakeOptions {
  std::string type, params = "{}", output, kind = "fiber";
  int resolution = 16, samples = 16, threads = 0;
  uint64_t seed = 1;
  bool quiet = false, json = false;
};

int run_bake(const BakeOptions& o, const RunLimits& limits) {
  const nlohmann::json params = parse_json(o.params, "--params");
  // Fail before the work, not after it; the files the parameters name (a table, a measured
  // network) are inputs.
  validate_output_paths(limits, {{o.output, "--output"}},
                        json_named_files(params, "--params file"));
  TabulatedBsdfTable::check_output_path(o.output, "--output");
  MaterialContext ctx;
  ctx.field_prefix = "--params";
  const Bsdf bsdf = make_bsdf(o.type, params, ctx);
  auto t = TabulatedBsdfTable::from_function(
      o.resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb f = bsdf.eval(wo, wi);
        v[0] = f.r, v[1] = f.g, v[2] = f.b;
      },
      o.samples, o.seed, o.threads, progress_bar(limits, o.quiet));
  t.kind = o.kind;
  const std::string spec = o.type + " " + params.dump();
  t.metadata = {{"source", "analytic " + spec},
                {"spec_hash", hex64(fnv1a64(spec))},
                {"seed", std::to_string(o.seed)},
                {"samples_per_cell", std::to_string(o.samples)},
                {"program_version", std::string("weft ") + WEFT_VERSION}};
  t.write_exr(o.output);
  if (o.json) {
    std::cout << nlohmann::json{{"output", o.output},
                                {"resolution", t.resolution},
                                {"kind", t.kind},
                                {"spec_hash", t.metadata["spec_hash"]},
                                {"checksum", t.checksum()}}
                     .dump(2)
              << "\n";
  }
  return 0;
}

}  // namespace

void add_table_command(CLI::App& app, Commands& commands) {
  auto* table = app.add_subcommand("table", "Tabulated BSDF tables (.exr): inspect or bake");
  table->require_subcommand(1);

  auto info = std::make_shared<InfoOptions>();
  auto* info_cmd =
      table->add_subcommand("info", "Validate a table and print its header and figures");
  info_cmd->add_option("file", info->file, "table .exr")->required();
  info_cmd->add_flag("--json", info->json, "print JSON with stable keys");
  commands.push_back({info_cmd, [info](const RunLimits&) { return run_info(*info); }});

  auto bake = std::make_shared<BakeOptions>();
  auto* bake_cmd = table->add_subcommand(
      "bake", "Bake an analytic material (e.g. classic_fiber) into an RGB table, as a reference");
  bake_cmd->add_option("type", bake->type, "material type, as in a scene")->required();
  bake_cmd->add_option("--params", bake->params, "material parameters as a JSON object");
  bake_cmd->add_option("-R,--resolution", bake->resolution, "bins per side for each direction")
      ->check(CLI::Range(1, TabulatedBsdfTable::kMaxResolution));
  bake_cmd->add_option("--spp", bake->samples, "stratified samples per cell pair")
      ->check(CLI::Range(1, 1 << 16));
  bake_cmd->add_option("--kind", bake->kind, "fiber or fabric")
      ->check(CLI::IsMember({"fiber", "fabric"}));
  bake_cmd->add_option("--seed", bake->seed, "random seed");
  bake_cmd->add_option("--threads", bake->threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, 4096));
  bake_cmd->add_option("-o,--output", bake->output, "output .exr")->required();
  bake_cmd->add_flag("--quiet", bake->quiet, "no progress bar");
  bake_cmd->add_flag("--json", bake->json, "print a JSON summary");
  commands.push_back({bake_cmd, [bake](const RunLimits& l) { return run_bake(*bake, l); }});
}

}  // namespace weft::cli
