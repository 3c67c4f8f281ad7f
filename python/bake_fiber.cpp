// weft.bake_fiber: the fiber bake's request (fiber/fiber_bake_request.h), planned with the checks
// `weft bake fiber` makes before the work and run with the GIL released.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fiber_colour.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/fiber_bake_request.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft_python.h"

namespace weft::python {

// The JSON text of a Python dict, by Python's json (its numbers as Python writes them).
nlohmann::json dict_json(const py::dict& d, const std::string& what) {
  const std::string text = py::module_::import("json").attr("dumps")(d).cast<std::string>();
  return parse_json(text, what);
}

Table bake_fiber_checked(const FiberSpec& spec, const FiberTableBakeOptions& o, bool yes_long,
                         bool print) {
  check_fiber_bake(call_limits(yes_long), o, kNumBands, {"", "photons", "resolution"});
  CallProgress progress(print);
  FiberTableBakeResult r;
  {
    py::gil_scoped_release release;
    r = bake_fiber_table(spec, o, progress.callback());
  }
  progress.raise_if_interrupted();
  r.table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION + " (python)";
  return Table(std::move(r.table));
}

namespace {

// A request's bake: planned (every check of `weft bake fiber`) and run without the GIL.
Table bake_fiber(const py::object& spec, FiberBakeRequest r, bool yes_long, bool print) {
  if (py::isinstance<py::dict>(spec))
    r.spec_read = fiber_spec_argument(spec);
  else
    r.spec = py::isinstance<py::str>(spec) ? spec.cast<std::string>()
                                           : spec.cast<std::filesystem::path>().string();
  r.limits = call_limits(yes_long);
  const ColouredFiberBakePlan plan = plan_coloured_fiber_bake(r);
  CallProgress progress(print);
  FiberBakeHooks hooks{progress.callback(), [&progress] { return progress.interrupted(); }};
  FiberBakeOutcome out;
  {
    py::gil_scoped_release release;
    out = run_coloured_fiber_bake(plan, hooks);
  }
  progress.raise_if_interrupted();
  out.table->table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION + " (python)";
  return Table(std::move(out.table->table));
}

}  // namespace

FiberSpec fiber_spec_argument(const py::object& spec) {
  if (py::isinstance<py::dict>(spec))
    return parse_fiber_spec(dict_json(spec.cast<py::dict>(), "spec").dump(), "spec");
  if (py::isinstance<py::str>(spec)) return load_fiber_spec(spec.cast<std::string>());
  return load_fiber_spec(spec.cast<std::filesystem::path>().string());
}

void bind_bake_fiber(py::module_& m) {
  const FiberBakeRequest d;
  m.def(
      "bake_fiber",
      [](const py::object& spec, uint64_t photons, int resolution, uint64_t seed, int threads,
         const std::string& bands, const std::string& route, uint64_t passes,
         std::optional<std::string> estimator, bool mirror_fold, std::optional<int> surface_samples,
         std::optional<std::string> entry, const std::string& surface_lobe,
         const std::string& colour, const std::string& colour_weave, bool yes_long, bool progress) {
        FiberBakeRequest r;
        r.photons = photons, r.resolution = resolution, r.seed = seed, r.threads = threads;
        r.bands = bands, r.route = route, r.passes = passes, r.estimator = estimator;
        r.mirror_fold = mirror_fold, r.surface_samples = surface_samples, r.entry = entry;
        r.surface_lobe = surface_lobe, r.colour = colour, r.colour_weave = colour_weave;
        return bake_fiber(spec, std::move(r), yes_long, progress);
      },
      py::arg("spec"), py::kw_only(), py::arg("photons") = d.photons,
      py::arg("resolution") = d.resolution, py::arg("seed") = d.seed,
      py::arg("threads") = d.threads, py::arg("bands") = d.bands, py::arg("route") = d.route,
      py::arg("passes") = d.passes, py::arg("estimator") = d.estimator,
      py::arg("mirror_fold") = d.mirror_fold, py::arg("surface_samples") = d.surface_samples,
      py::arg("entry") = d.entry, py::arg("surface_lobe") = d.surface_lobe,
      py::arg("colour") = d.colour, py::arg("colour_weave") = d.colour_weave,
      py::arg("yes_long") = false, py::arg("progress") = false,
      "Bakes a fiber spec (a dict, a spec file or a preset name) into a fiber table, as `weft "
      "bake fiber` does; estimator, surface_samples and entry None: the spec's and route's "
      "default; surface_lobe \"sampled\" or \"analytic\" (`--surface-lobe`); colour (any "
      "`--colour` form) scales the spec's dyes first so that a cloth of the fiber (colour_weave, "
      "the bundled poplin when empty) meets it, the table's metadata \"colour\" says how near. "
      "Work estimated above an hour needs yes_long=True.");
}

}  // namespace weft::python
