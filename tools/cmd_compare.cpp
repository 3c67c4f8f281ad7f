// weft compare: how far apart two BSDF tables are (relative RMS and largest relative difference,
// overall, in reflection and in transmission) and their in-plane curves.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/materials/table_compare.h"
#include "weft/verify/plot_scripts.h"

namespace weft::cli {
namespace {

struct CompareCliOptions {
  std::string a, b, plot, csv;
  bool json = false;
  CompareOptions compare;
};

// A side where the reference holds no light has no relative difference: null, not 0.
nlohmann::json to_json(const TableDifference& d) {
  const auto relative = [&](double v) {
    return d.reference_has_light ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  return {{"rel_rms", relative(d.rel_rms)},
          {"max_rel", relative(d.max_rel)},
          {"abs_rms", d.abs_rms},
          {"reference_zero", !d.reference_has_light},
          {"cells", d.cells}};
}

void print_difference(const char* name, const TableDifference& d) {
  if (d.reference_has_light)
    std::printf("  %-13s rel_rms %.4f  max_rel %.4f  (%zu cell pairs)\n", name, d.rel_rms,
                d.max_rel, d.cells);
  else
    std::printf(
        "  %-13s undefined: the reference is zero on this side; B's RMS f there %.4g  "
        "(%zu cell pairs)\n",
        name, d.abs_rms, d.cells);
}

int run_compare(const CompareCliOptions& o, const RunLimits& limits) {
  validate_output_paths(limits, {{o.plot, "--plot"}, {o.csv, "--csv"}},
                        {{o.a, "table A"}, {o.b, "table B"}});
  const auto a = TabulatedBsdfTable::read_exr(o.a);
  const auto b = TabulatedBsdfTable::read_exr(o.b);
  check_compare_reference(a, o.a);
  const TableComparison c = compare_tables(a, b, o.compare);
  const std::string curves = in_plane_csv(c, a.channel_names());
  if (!o.csv.empty()) write_text_atomically(o.csv, curves);
  if (!o.plot.empty()) {
    // The curves for the plot script under a name of this run's own (atomic_file.h), so that
    // runs at once never read each other's; removed however the plot ends.
    const auto tmp =
        temporary_sibling(std::filesystem::temp_directory_path() / "weft-compare-curves.csv");
    struct Remove {
      std::filesystem::path path;
      ~Remove() {
        std::error_code ec;
        std::filesystem::remove(path, ec);
      }
    } remove{tmp};
    write_text_atomically(tmp, curves);
    // Ctrl-C ends the script (which writes the plot whole or not at all) and the command.
    if (!run_plot_script("plot_compare.py",
                         {tmp.string(), o.plot, std::filesystem::path(o.a).filename().string(),
                          std::filesystem::path(o.b).filename().string()},
                         o.plot, polled_interrupt())) {
      std::fprintf(stderr, "\nweft: compare cancelled; the plot was not written\n");
      return 130;
    }
  }
  if (o.json) {
    std::cout << nlohmann::json{{"a", o.a},
                                {"b", o.b},
                                {"overall", to_json(c.overall)},
                                {"reflection", to_json(c.reflection)},
                                {"transmission", to_json(c.transmission)},
                                {"in_plane_rel_rms", std::isnan(c.in_plane_rel_rms)
                                                         ? nlohmann::json(nullptr)
                                                         : nlohmann::json(c.in_plane_rel_rms)},
                                {"significant", o.compare.significant}}
                     .dump(2)
              << "\n";
  } else {
    std::printf("%s vs %s (reference %s)\n", o.b.c_str(), o.a.c_str(), o.a.c_str());
    print_difference("overall", c.overall);
    print_difference("reflection", c.reflection);
    print_difference("transmission", c.transmission);
    if (std::isnan(c.in_plane_rel_rms))
      std::printf("  in-plane      undefined: the reference's in-plane curves are zero\n");
    else
      std::printf("  in-plane      rel_rms %.4f\n", c.in_plane_rel_rms);
  }
  return 0;
}

}  // namespace

void add_compare_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<CompareCliOptions>();
  auto* sub = app.add_subcommand(
      "compare",
      "Compare two BSDF tables (.exr): relative RMS and largest relative difference "
      "of B against the reference A, overall, in reflection and in transmission");
  sub->add_option("a", o->a, "reference table (.exr)")->required();
  sub->add_option("b", o->b, "table to compare (.exr)")->required();
  sub->add_flag("--json", o->json, "print JSON with stable keys");
  sub->add_option("--plot", o->plot, "in-plane curves as a plot (.png or .svg)");
  sub->add_option("--csv", o->csv, "in-plane curves as CSV");
  sub->add_option("--significant", o->compare.significant,
                  "max_rel counts cells at least this fraction of A's mean value")
      ->check(finite_range(0.0, 1e6))
      ->capture_default_str();
  commands.push_back({sub, [o](const RunLimits& l) { return run_compare(*o, l); }});
}

}  // namespace weft::cli
