// weft export: a table leaves Weft as a file other renderers read (docs/exchange.md): RGL .bsdf
// (Mitsuba 3, pbrt-v4), MDL .mbsdf (Omniverse / Iray), glTF 2.0 material (.gltf / .glb), or a
// self-contained .html page previewing that material.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/exchange/export_table.h"
#include "weft/materials/bsdf_table.h"

namespace weft::cli {
namespace {

struct ExportCliOptions {
  std::string table, output, name;
  bool json = false;
};

int run_export(const ExportCliOptions& o, const RunLimits& limits) {
  check_export_path(o.output, "--output");
  validate_output_paths(limits, {{o.output, "--output"}}, {{o.table, "table"}});
  const auto table = TabulatedBsdfTable::read_exr(o.table);
  for (const auto& w : export_table_warnings(table, o.table))
    std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  ExportOptions options;
  options.name = o.name.empty() ? std::filesystem::path(o.table).stem().string() : o.name;
  return print_export_report(export_table(table, o.output, options), o.output, o.table, o.json);
}

}  // namespace

int print_export_report(const ExportReport& r, const std::string& output, const std::string& table,
                        bool json) {
  if (json) {
    nlohmann::json figures = nlohmann::json::object();
    for (const auto& [k, v] : r.figures) figures[k] = v;
    std::cout << nlohmann::json{{"output", output},
                                {"format", r.format},
                                {"dropped", r.dropped},
                                {"notes", r.notes},
                                {"figures", figures}}
                     .dump(2)
              << "\n";
    return 0;
  }
  std::cout << "wrote " << output << " (" << r.format << ") from " << table << "\n";
  for (const auto& [k, v] : r.figures) std::cout << "  " << k << ": " << v << "\n";
  for (const auto& d : r.dropped) std::cout << "  dropped: " << d << "\n";
  for (const auto& n : r.notes) std::cout << "  note: " << n << "\n";
  return 0;
}

void add_export_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<ExportCliOptions>();
  auto* sub = app.add_subcommand(
      "export",
      "Export a table for other renderers: RGL .bsdf (Mitsuba 3, pbrt-v4), MDL .mbsdf, glTF "
      "material (.gltf/.glb), or an offline .html page previewing it; prints what the format "
      "drops");
  sub->add_option("table", o->table, "table (.exr)")->required();
  sub->add_option("-o,--output", o->output, "output: .bsdf, .mbsdf, .gltf, .glb or .html")
      ->required();
  sub->add_option("--name", o->name, "material name (default: the table's file name)");
  sub->add_flag("--json", o->json, "print the summary as JSON");
  commands.push_back({sub, [o](const RunLimits& l) { return run_export(*o, l); }});
}

}  // namespace weft::cli
