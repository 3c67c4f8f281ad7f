// weft view: one offline page of any table, its in-plane curves with the incidence chosen on the
// page and, for a fabric table, the glTF material fitted to it in 3-D (docs/exchange.md). Binds the
// options to exchange/view_request.h and prints what the run returns.
#include <cstdio>

#include "commands.h"
#include "weft/exchange/view_request.h"

namespace weft::cli {
namespace {

struct ViewCliOptions {
  ViewRequest request;
  bool json = false;
};

int run_view_command(ViewCliOptions o, const RunLimits& limits) {
  o.request.limits = limits;
  const ViewPlan plan = plan_view(o.request);
  for (const auto& w : plan.warnings) std::fprintf(stderr, "weft: warning: %s\n", w.c_str());
  return print_export_report(run_view(plan), o.request.output, o.request.table, o.json);
}

}  // namespace

void add_view_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<ViewCliOptions>();
  auto* sub = app.add_subcommand(
      "view",
      "Write one offline .html page of a table: its in-plane curves, the incidence chosen on the "
      "page, and for a fabric table the glTF material fitted to it, in 3-D");
  sub->add_option("table", o->request.table, "table (.exr), fabric or fiber")->required();
  sub->add_option("-o,--output", o->request.output, "the page (.html)")->required();
  sub->add_option("--name", o->request.name, "title (default: the table's file name)");
  sub->add_flag("--json", o->json, "print the summary as JSON");
  commands.push_back({sub, [o](const RunLimits& l) { return run_view_command(*o, l); }});
}

}  // namespace weft::cli
