// weft.verify: `weft verify` from Python (verify/plan.h, verify/whole_run.h): the plan with its
// checks, the time check, the run without the GIL, the report folder with its plots, and
// its metrics.json as a dict.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/output_guard.h"
#include "weft/verify/plan.h"
#include "weft/verify/plot_scripts.h"
#include "weft/verify/report.h"
#include "weft/verify/whole_run.h"
#include "weft_python.h"

namespace weft::python {

namespace {

struct VerifyArgs {
  VerifyRequest request;
  bool plots = true, yes_long = false, progress = false;
};

// The plan, its output folder and its time checked before any work, as `weft verify` does.
VerifyPlan checked_plan(const VerifyArgs& a) {
  const VerifyRequest& r = a.request;
  const VerifyPlan p = plan_verify(r);
  const RunLimits limits = call_limits(a.yes_long);
  validate_output_paths(limits, {},
                        {{p.measured_path, "measured"},
                         {r.weave, "weave"},
                         {r.wif, "wif"},
                         {r.fiber, "fiber"},
                         {p.weave.wif.value_or(""), "wif"}},
                        {{r.output, "output"}});
  check_verify_output(r.output);
  check_long_work(limits, estimate_verify(p).least, 1.0, p.settings.threads, "", "quality",
                  "weft verify at quality " + r.quality + (r.fit ? " with fit" : ""),
                  kVerifyLeastRates);
  return p;
}

// The fit's options over the request's defaults; each one that differs from its default counts as
// given, and plan_verify refuses it without fit=True (as the command refuses --fit-* without
// --fit).
void set_fit_options(VerifyRequest& r, const std::string& params, int evaluations,
                     const std::string& inner, int seeds, const std::string& method) {
  const VerifyRequest d;
  r.fit_params_given = params != d.fit_params;
  r.fit_evaluations_given = evaluations != d.fit_evaluations;
  r.fit_inner_given = inner != d.fit_inner;
  r.fit_seeds_given = seeds != d.fit_seeds;
  r.fit_method_given = method != d.fit_method;
  r.fit_params = params;
  r.fit_evaluations = evaluations;
  r.fit_inner = inner;
  r.fit_seeds = seeds;
  r.fit_method = method;
}

py::dict verify(VerifyArgs a) {
  if (a.request.output.empty())
    a.request.output = py::module_::import("tempfile")
                           .attr("mkdtemp")(py::arg("prefix") = "weft-verify-")
                           .cast<std::string>();
  const VerifyPlan plan = checked_plan(a);
  CallProgress progress(a.progress);
  VerifyHooks hooks;
  hooks.progress = progress.callback();
  hooks.interrupted = [progress] { return progress.interrupted(); };
  hooks.note = [progress](const std::string& line) { progress.note(line); };
  const std::string output = a.request.output;
  const int threads = a.request.threads;
  if (a.plots)
    // Polled through the callback, which looks for Ctrl-C on the caller's thread (the script
    // runs in a process group of its own, which a Ctrl-C at the terminal does not reach).
    hooks.draw = [output, threads,
                  poll = progress.callback()](const std::filesystem::path& staging) {
      plot_verify_figures(staging, output, threads, [&poll] {
        return poll({"report", 2, 3, "steps"});
      });
    };
  VerifyOutcome out;
  {
    py::gil_scoped_release release;
    out = run_verify_plan(plan, hooks);
  }
  progress.raise_if_interrupted();
  if (out.cancelled) throw Error(output, "", "verify was cancelled; nothing was written");
  // The file as written (its renders and timings are the report's, not the run's).
  const std::filesystem::path file = std::filesystem::path(output) / "metrics.json";
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string(), "", "cannot read the report's metrics");
  std::stringstream text;
  text << in.rdbuf();
  py::dict metrics = py::module_::import("json").attr("loads")(text.str());
  metrics["report_folder"] = output;
  return metrics;
}

}  // namespace

void bind_verify(py::module_& m) {
  m.def(
      "verify",
      [](const std::string& quality, const std::optional<std::filesystem::path>& output,
         const py::object& fiber, const std::optional<std::string>& measured,
         const std::optional<std::string>& colour_space, const std::optional<std::string>& weave,
         const std::optional<std::string>& pattern, const std::optional<std::string>& wif,
         uint64_t seed, int threads, const std::optional<std::string>& classic_albedo,
         const std::optional<std::string>& colour, const std::optional<std::string>& colour_from,
         bool fit, const std::string& fit_params, int fit_evaluations, const std::string& fit_inner,
         int fit_seeds, const std::string& fit_method, bool plots, bool yes_long, bool progress) {
        VerifyArgs a;
        VerifyRequest& r = a.request;
        r.quality = quality;
        r.output = output ? output->string() : "";
        r.fiber = fiber.cast<std::filesystem::path>().string();
        r.measured = measured.value_or("");
        r.colour_space = colour_space.value_or("");
        r.weave = weave.value_or("");
        r.pattern = pattern.value_or("");
        r.wif = wif.value_or("");
        r.seed = seed;
        r.threads = threads;
        r.classic_albedo = classic_albedo.value_or("");
        r.colour = colour.value_or("");
        r.colour_from = colour_from.value_or("");
        r.fit = fit;
        set_fit_options(r, fit_params, fit_evaluations, fit_inner, fit_seeds, fit_method);
        a.plots = plots;
        a.yes_long = yes_long;
        a.progress = progress;
        return verify(std::move(a));
      },
      py::arg("quality") = VerifyRequest{}.quality, py::kw_only(), py::arg("output") = py::none(),
      py::arg("fiber") = VerifyRequest{}.fiber, py::arg("measured") = py::none(),
      py::arg("colour_space") = py::none(), py::arg("weave") = py::none(),
      py::arg("pattern") = py::none(), py::arg("wif") = py::none(),
      py::arg("seed") = VerifyRequest{}.seed, py::arg("threads") = 0,
      py::arg("classic_albedo") = py::none(), py::arg("colour") = py::none(),
      py::arg("colour_from") = py::none(), py::arg("fit") = false,
      py::arg("fit_params") = VerifyRequest{}.fit_params,
      py::arg("fit_evaluations") = VerifyRequest{}.fit_evaluations,
      py::arg("fit_inner") = VerifyRequest{}.fit_inner,
      py::arg("fit_seeds") = VerifyRequest{}.fit_seeds,
      py::arg("fit_method") = VerifyRequest{}.fit_method, py::arg("plots") = true,
      py::arg("yes_long") = false, py::arg("progress") = false,
      "`weft verify` (docs/verify.md): the computed fabric, the paper's summation and the "
      "classic model against a measurement. Writes the report folder 'output' (default: a new "
      "temporary folder) and returns its metrics.json as a dict, with 'report_folder' added.");
}

}  // namespace weft::python
