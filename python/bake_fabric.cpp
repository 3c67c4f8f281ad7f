// weft.bake_fabric: the fabric tables (fabric/), with the checks `weft bake fabric` makes before
// the work and the GIL released while the libraries work.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fabric/fabric_parts.h"
#include "weft/fabric/fabric_raytrace.h"
#include "weft/fabric/fabric_summation.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/scenes/weave.h"
#include "weft_python.h"

namespace weft::python {

namespace {

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
  check_fabric_bake(call_limits(yes_long), value_of(kFabricMethods, a.method, "", "method"),
                    a.resolution, bins, a.samples, a.threads, "samples");
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

void bind_bake_fabric(py::module_& m) {
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
