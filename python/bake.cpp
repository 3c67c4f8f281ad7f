// weft.bake_fiber and weft.bake_fabric: the fiber bake (fiber/fiber_table_bake.h) and the fabric
// tables (fabric/), with the checks `weft bake fiber` and `weft bake fabric` make before the work
// (tools/cli_util.h) and the GIL released while the libraries work.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>

#include "cli_util.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/scenes/weave.h"
#include "weft_python.h"

namespace weft::python {

namespace {

// The JSON text of a Python dict, by Python's json (its numbers as Python writes them).
nlohmann::json dict_json(const py::dict& d, const std::string& what) {
  const std::string text = py::module_::import("json").attr("dumps")(d).cast<std::string>();
  return parse_json(text, what);
}

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

// The bake itself, checked (memory, time) and run without the GIL.
Table bake_fiber_checked(const FiberSpec& spec, const FiberTableBakeOptions& o, bool yes_long,
                         bool print) {
  check_with_limits(yes_long, [&] {
    cli::check_fiber_bake(o, kNumBands, {"", "photons", "resolution"});
  });
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

Table bake_fiber(const py::object& spec, const FiberBakeArgs& a, bool yes_long, bool print) {
  const FiberSpec s = fiber_spec_argument(spec);
  return bake_fiber_checked(s, fiber_bake_options(s, a), yes_long, print);
}

// bake_fabric's fiber: a Table, a table file (.exr), or a spec baked here at the bake's defaults
// in RGB (as `weft bake fabric --fiber SPEC` bakes one into its cache).
Table fabric_fiber(const py::object& fiber, bool yes_long, bool print) {
  if (py::isinstance<Table>(fiber)) return fiber.cast<Table>();
  if (py::isinstance<py::str>(fiber) ||
      py::isinstance(fiber, py::module_::import("os").attr("PathLike"))) {
    const std::filesystem::path p = fiber.cast<std::filesystem::path>();
    if (p.extension() == ".exr") return Table(TabulatedBsdfTable::read_exr(p));
  }
  const FiberSpec spec = fiber_spec_argument(fiber);
  FiberTableBakeOptions o = fiber_bake_defaults(spec);
  o.spectral = false;
  return bake_fiber_checked(spec, o, yes_long, print);
}

// The woven sample: the bundled poplin, a weave options file or dict (`weft weave`'s options),
// with a pattern or WIF draft and the detail over it.
WovenSample woven_sample(const py::object& sample, const std::optional<std::string>& pattern,
                         const std::optional<std::string>& wif, const std::string& detail) {
  WeaveOptions base;
  if (py::isinstance<py::dict>(sample)) {
    const nlohmann::json j = dict_json(sample.cast<py::dict>(), "sample");
    ParamReader r(j, "sample", "");
    base = read_weave_options(r, std::filesystem::current_path());
  } else if (!sample.is_none()) {
    base = read_weave_options(sample.cast<std::filesystem::path>());
  }
  if (pattern && wif) throw Error("", "wif", "give either pattern or wif, not both");
  WeaveOptions given;
  given.pattern = pattern;
  given.wif = wif;
  given.detail = detail;
  return make_woven_sample(overlay(base, given));
}

std::vector<FiberOrientation> orientations(const std::vector<Vec3>& tangents) {
  std::vector<FiberOrientation> out;
  for (const Vec3& t : tangents) out.push_back({t, 1.0});
  return out;
}

struct FabricBakeArgs {
  std::string method = "summation", detail = "yarn";
  std::optional<std::string> pattern, wif;
  int resolution = 8, threads = 0;
  std::optional<uint64_t> samples;
  uint64_t seed = 1;
};

// The table by the method asked for, without the GIL.
TabulatedBsdfTable fabric_table(const TabulatedBsdfTable& fiber, const WovenSample& sample,
                                const FabricBakeArgs& a, const ProgressCallback& progress) {
  if (a.method == "raytrace") {
    FabricRaytraceOptions r;
    r.resolution = a.resolution;
    if (a.samples) r.particles_per_bin = *a.samples;
    r.seed = a.seed;
    r.threads = a.threads;
    r.validate();
    py::gil_scoped_release release;
    FabricRaytraceResult res = raytrace_fabric_table(sample, fiber, r, progress);
    record_particle_counts(res.table, res.splits, res.roulette_kills);
    return std::move(res.table);
  }
  FabricSummationOptions s;
  s.method = a.method == "summation" ? FabricSummation::kPaper : FabricSummation::kVisible;
  s.resolution = a.resolution;
  if (a.samples) s.samples_per_cell = static_cast<int>(*a.samples);  // checked in bake_fabric
  s.seed = a.seed;
  s.threads = a.threads;
  if (s.method == FabricSummation::kVisible) {
    s.top = orientations(visible_fiber_tangents(sample, true));
    s.bottom = orientations(visible_fiber_tangents(sample, false));
  }
  s.validate();
  py::gil_scoped_release release;
  return sum_fabric_table(fiber, s, progress);
}

Table bake_fabric(const py::object& fiber, const py::object& sample, const FabricBakeArgs& a,
                  bool yes_long, bool print) {
  if (a.method != "summation" && a.method != "summation-visible" && a.method != "raytrace")
    throw Error("", "method",
                "must be 'summation', 'summation-visible' or 'raytrace', got '" + a.method + "'");
  if (a.detail != "yarn" && a.detail != "fiber")
    throw Error("", "detail", "must be 'yarn' or 'fiber', got '" + a.detail + "'");
  if (a.resolution < 1 || a.resolution > TabulatedBsdfTable::kMaxResolution)
    throw Error("", "resolution", "must be in [1, 32], got " + std::to_string(a.resolution));
  // Checked before narrowing to the summation's int (2^32 + 1 would wrap to 1).
  if (a.method != "raytrace" && a.samples && (*a.samples < 1 || *a.samples > 4096))
    throw Error("", "samples",
                "a summation takes 1 to 4096 direction pairs per cell pair, got " +
                    std::to_string(*a.samples));
  const uint64_t bins = static_cast<uint64_t>(DirectionGrid{a.resolution}.bins());
  check_with_limits(yes_long, [&] {
    cli::check_fabric_bake(a.method, a.resolution, bins, a.samples, a.threads, "samples");
  });
  const Table fiber_table = fabric_fiber(fiber, yes_long, print);
  const WovenSample woven = woven_sample(sample, a.pattern, a.wif, a.detail);
  CallProgress progress(print);
  TabulatedBsdfTable table = fabric_table(fiber_table.get(), woven, a, progress.callback());
  progress.raise_if_interrupted();
  table.metadata["sample"] = woven.summary.source + " (" + woven.summary.detail + ")";
  table.metadata["program_version"] = std::string("weft ") + WEFT_VERSION + " (python)";
  return Table(std::move(table));
}

}  // namespace

FiberSpec fiber_spec_argument(const py::object& spec) {
  if (py::isinstance<py::dict>(spec))
    return parse_fiber_spec(dict_json(spec.cast<py::dict>(), "spec").dump(), "spec");
  if (py::isinstance<py::str>(spec)) return load_fiber_spec(spec.cast<std::string>());
  return load_fiber_spec(spec.cast<std::filesystem::path>().string());
}

void bind_bake(py::module_& m) {
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
  m.def(
      "bake_fabric",
      [](const py::object& fiber, const std::string& method, const py::object& sample,
         std::optional<std::string> pattern, std::optional<std::string> wif,
         const std::string& detail, int resolution, std::optional<uint64_t> samples, uint64_t seed,
         int threads, bool yes_long, bool progress) {
        FabricBakeArgs a{method,  detail, std::move(pattern), std::move(wif), resolution, threads,
                         samples, seed};
        return bake_fabric(fiber, sample, a, yes_long, progress);
      },
      py::arg("fiber"), py::arg("method") = "summation", py::kw_only(),
      py::arg("sample") = py::none(), py::arg("pattern") = py::none(), py::arg("wif") = py::none(),
      py::arg("detail") = "yarn", py::arg("resolution") = 8, py::arg("samples") = py::none(),
      py::arg("seed") = 1, py::arg("threads") = 0, py::arg("yes_long") = false,
      py::arg("progress") = false,
      "A fabric table from a fiber table (a Table, a .exr file, or a spec baked in RGB at the "
      "bake's defaults) and a woven sample (None: the bundled poplin; a weave options file or "
      "dict), by 'summation' (the paper's), 'summation-visible' or 'raytrace', as `weft bake "
      "fabric` does.");
}

}  // namespace weft::python
