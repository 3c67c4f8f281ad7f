// weft table: inspect tabulated BSDF tables (info) and bake analytic materials into them (bake),
// binding the options to materials/table_request.h and printing.
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
#include "weft/materials/table_request.h"

namespace weft::cli {
namespace {

struct InfoOptions {
  std::string file;
  bool json = false;
};

int run_info(const InfoOptions& o) {
  const nlohmann::json j = table_info(TabulatedBsdfTable::read_exr(o.file), o.file);
  if (o.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    for (const auto& [k, v] : j.items()) std::cout << k << ": " << v.dump() << "\n";
  }
  return 0;
}

struct BakeOptions {
  TableBakeRequest request;
  bool quiet = false, json = false;
};

int run_bake(BakeOptions o, const RunLimits& limits) {
  o.request.limits = limits;
  const TableBakePlan plan = plan_table_bake(o.request);
  TabulatedBsdfTable t = run_table_bake(plan, progress_bar(limits, o.quiet));
  t.metadata["program_version"] = std::string("weft ") + WEFT_VERSION;
  const std::string& output = o.request.output;
  t.write_exr(output);
  if (o.json) {
    std::cout << nlohmann::json{{"output", output},
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
  bake_cmd->add_option("type", bake->request.type, "material type, as in a scene")->required();
  bake_cmd->add_option("--params", bake->request.params, "material parameters as a JSON object");
  bake_cmd
      ->add_option("-R,--resolution", bake->request.resolution, "bins per side for each direction")
      ->check(CLI::Range(1, TabulatedBsdfTable::kMaxResolution));
  bake_cmd->add_option("--spp", bake->request.samples, "stratified samples per cell pair")
      ->check(CLI::Range(1, 1 << 16));
  bake_cmd->add_option("--kind", bake->request.kind, "fiber or fabric")
      ->check(CLI::IsMember({"fiber", "fabric"}));
  bake_cmd->add_option("--seed", bake->request.seed, "random seed");
  bake_cmd->add_option("--threads", bake->request.threads, "worker threads (0 = all)")
      ->check(CLI::Range(0, 4096));
  bake_cmd->add_option("-o,--output", bake->request.output, "output .exr")->required();
  bake_cmd->add_flag("--quiet", bake->quiet, "no progress bar");
  bake_cmd->add_flag("--json", bake->json, "print a JSON summary");
  commands.push_back({bake_cmd, [bake](const RunLimits& l) { return run_bake(*bake, l); }});
}

}  // namespace weft::cli
