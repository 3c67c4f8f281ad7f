// weft.bake_fiber: the fiber bake (fiber/fiber_table_bake.h), with the checks `weft bake fiber`
// makes before the work and the GIL released while the library works.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fiber/bake_cache.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft_python.h"

namespace weft::python {

// The JSON text of a Python dict, by Python's json (its numbers as Python writes them).
nlohmann::json dict_json(const py::dict& d, const std::string& what) {
  const std::string text = py::module_::import("json").attr("dumps")(d).cast<std::string>();
  return parse_json(text, what);
}

namespace {

struct FiberBakeArgs {
  uint64_t photons = FiberTableBakeOptions{}.photons_per_band;
  int resolution = FiberTableBakeOptions{}.resolution;
  uint64_t seed = FiberTableBakeOptions{}.seed, passes = FiberTableBakeOptions{}.passes;
  int threads = 0;
  std::string bands = "spectral", route = "direct";
};

// The options of a bake, each checked against the range `weft bake fiber` allows, over the
// spec's and route's defaults (fiber_bake_defaults).
FiberTableBakeOptions fiber_bake_options(const FiberSpec& spec, const FiberBakeArgs& a) {
  if (a.photons < 1 || a.photons > kMaxPhotonsPerBand)
    throw Error("", "photons", "must be in [1, 2^40], got " + std::to_string(a.photons));
  if (a.resolution < 2 || a.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution",
                "must be in [2, " + std::to_string(TabulatedBsdfTable::kMaxResolution) + "], got " +
                    std::to_string(a.resolution));
  if (a.passes < 1 || a.passes > (uint64_t{1} << 20))
    throw Error("", "passes", "must be in [1, 2^20], got " + std::to_string(a.passes));
  if (a.threads < 0) throw Error("", "threads", "must be 0 (all cores) or more");
  if (a.bands != "spectral" && a.bands != "rgb")
    throw Error("", "bands", "must be 'spectral' or 'rgb', got '" + a.bands + "'");
  if (a.route != "direct" && a.route != "bssrdf")
    throw Error("", "route", "must be 'direct' or 'bssrdf', got '" + a.route + "'");
  FiberTableBakeOptions o = fiber_bake_defaults(
      spec, a.route == "direct" ? FiberBakeRoute::kDirect : FiberBakeRoute::kBssrdf);
  o.photons_per_band = a.photons;
  o.resolution = a.resolution;
  o.seed = a.seed;
  o.passes = a.passes;
  o.threads = a.threads;
  o.spectral = a.bands == "spectral";
  return o;
}

}  // namespace

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

Table bake_fiber(const py::object& spec, const FiberBakeArgs& a, bool yes_long, bool print) {
  const FiberSpec s = fiber_spec_argument(spec);
  return bake_fiber_checked(s, fiber_bake_options(s, a), yes_long, print);
}

}  // namespace

FiberSpec fiber_spec_argument(const py::object& spec) {
  if (py::isinstance<py::dict>(spec))
    return parse_fiber_spec(dict_json(spec.cast<py::dict>(), "spec").dump(), "spec");
  if (py::isinstance<py::str>(spec)) return load_fiber_spec(spec.cast<std::string>());
  return load_fiber_spec(spec.cast<std::filesystem::path>().string());
}

void bind_bake_fiber(py::module_& m) {
  m.def(
      "bake_fiber",
      [](const py::object& spec, uint64_t photons, int resolution, uint64_t seed, int threads,
         const std::string& bands, const std::string& route, uint64_t passes, bool yes_long,
         bool progress) {
        return bake_fiber(spec, {photons, resolution, seed, passes, threads, bands, route},
                          yes_long, progress);
      },
      py::arg("spec"), py::kw_only(), py::arg("photons") = FiberTableBakeOptions{}.photons_per_band,
      py::arg("resolution") = FiberTableBakeOptions{}.resolution,
      py::arg("seed") = FiberTableBakeOptions{}.seed, py::arg("threads") = 0,
      py::arg("bands") = "spectral", py::arg("route") = "direct",
      py::arg("passes") = FiberTableBakeOptions{}.passes, py::arg("yes_long") = false,
      py::arg("progress") = false,
      "Bakes a fiber spec (a dict, a spec file or a preset name) into a fiber table, as `weft "
      "bake fiber` does. Work estimated above an hour needs yes_long=True.");
}

}  // namespace weft::python
