// weft.bake_fabric: the fabric library's bake (fabric/fabric_bake.h) with the request of `weft
// bake fabric`, its keyword arguments the command's options and their defaults the request's, the
// GIL released while the library works.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <variant>

#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/fabric/fabric_bake.h"
#include "weft/fabric/fabric_fibers.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/scenes/weave.h"
#include "weft_python.h"

namespace weft::python {

namespace {

bool is_path(const py::object& x) {
  return py::isinstance<py::str>(x) ||
         py::isinstance(x, py::module_::import("os").attr("PathLike"));
}

// The fiber into the request: a Table as it is, a table file (.exr) or a spec named for the
// library. A spec (a dict, or a name without --thread-colours, which dyes it) is baked here in
// memory once the plan has passed (baked_fiber), not into the bake cache.
void request_fiber(const py::object& fiber, FabricBakeRequest& r) {
  r.fiber.clear();
  if (py::isinstance<Table>(fiber))
    r.fiber_table = fiber.cast<Table>().shared();
  else if (is_path(fiber))
    r.fiber = fiber.cast<std::filesystem::path>().string();
  else if (r.thread_colours || !r.colour.empty())
    throw Error("", r.thread_colours ? "--thread-colours" : "--colour",
                "dyes a fiber spec or preset given by its name or file, not a dict");
}

std::shared_ptr<const TabulatedBsdfTable> baked_fiber(const py::object& fiber,
                                                      const FabricBakeRequest& r, bool print) {
  // Thread colours and a colour match bake their own dyed fibers into the cache.
  if (r.fiber_table || r.thread_colours || !r.colour.empty()) return r.fiber_table;
  if (is_path(fiber) && std::filesystem::path(r.fiber).extension() == ".exr") return nullptr;
  const FiberSpec spec = fiber_spec_argument(fiber);
  return bake_fiber_checked(spec, fabric_fiber_bake_options(spec), r.limits.yes_long, print)
      .shared();
}

// The woven sample's options: None (the bundled poplin), a weave options file or a dict of them.
void request_sample(const py::object& sample, FabricBakeRequest& r) {
  if (py::isinstance<py::dict>(sample)) {
    const nlohmann::json j = dict_json(sample.cast<py::dict>(), "sample");
    ParamReader reader(j, "sample", "");
    r.weave_options = read_weave_options(reader, std::filesystem::current_path());
  } else if (!sample.is_none()) {
    r.weave = sample.cast<std::filesystem::path>().string();
  }
}

using Positions = std::variant<int, std::string>;

Table bake_fabric(const py::object& fiber, const py::object& sample, FabricBakeRequest r,
                  bool print) {
  request_fiber(fiber, r);
  request_sample(sample, r);
  FabricBakePlan plan = plan_fabric_bake(r);
  plan.fibers.fiber_table = baked_fiber(fiber, plan.request, print);
  CallProgress progress(print);
  FabricBakeResult result;
  {
    py::gil_scoped_release release;
    result = run_fabric_bake(plan, {progress.callback()});
  }
  progress.raise_if_interrupted();
  return Table(std::move(result.table));
}

}  // namespace

void bind_bake_fabric(py::module_& m) {
  const FabricBakeRequest d;
  m.def(
      "bake_fabric",
      [](const py::object& fiber, const std::string& method, std::optional<std::string> warp_fiber,
         std::optional<std::string> weft_fiber, bool thread_colours,
         std::optional<std::string> thread_colour_method, std::optional<std::string> colour,
         const py::object& sample, std::optional<std::string> pattern,
         std::optional<std::string> wif, std::optional<std::string> detail, int resolution,
         std::optional<uint64_t> samples, std::optional<std::string> estimator,
         std::optional<int> next_event_rays, std::optional<int> launch_lattice,
         std::optional<std::string> straight_through, std::optional<double> split_threshold,
         std::optional<int> max_scatterings, std::optional<std::filesystem::path> weave_out,
         std::optional<Positions> weave_positions, std::optional<int> weave_resolution,
         std::optional<int> sheen_resolution, std::optional<int> sheen_window,
         std::optional<int> sheen_light_resolution, std::optional<std::string> sheen_light,
         uint64_t seed, int threads, bool yes_long, bool progress) {
        FabricBakeRequest r;
        r.method = method;
        r.warp_fiber = warp_fiber.value_or(""), r.weft_fiber = weft_fiber.value_or("");
        r.thread_colours = thread_colours;
        r.thread_colour_method = std::move(thread_colour_method);
        r.colour = colour.value_or("");
        r.pattern = pattern.value_or(""), r.wif = wif.value_or("");
        r.detail = detail;
        r.resolution = resolution;
        r.samples = samples;
        r.estimator = std::move(estimator);
        r.next_event_rays = next_event_rays, r.launch_lattice = launch_lattice;
        r.straight_through = std::move(straight_through);
        r.split_threshold = split_threshold, r.max_scatterings = max_scatterings;
        if (weave_out) r.weave_out = weave_out->string();
        if (weave_positions)
          r.weave_positions = std::visit(
              [](const auto& p) {
                if constexpr (std::is_same_v<std::decay_t<decltype(p)>, int>)
                  return std::to_string(p);
                else
                  return p;
              },
              *weave_positions);
        r.weave_resolution = weave_resolution;
        r.sheen_resolution = sheen_resolution, r.sheen_window = sheen_window;
        r.sheen_light_resolution = sheen_light_resolution;
        r.sheen_light = std::move(sheen_light);
        r.seed = seed, r.threads = threads;
        r.front_end = "python";
        r.limits = call_limits(yes_long);
        return bake_fabric(fiber, sample, std::move(r), progress);
      },
      py::arg("fiber") = d.fiber, py::arg("method") = d.method, py::kw_only(),
      py::arg("warp_fiber") = py::none(), py::arg("weft_fiber") = py::none(),
      py::arg("thread_colours") = d.thread_colours, py::arg("thread_colour_method") = py::none(),
      py::arg("colour") = py::none(), py::arg("sample") = py::none(),
      py::arg("pattern") = py::none(), py::arg("wif") = py::none(), py::arg("detail") = py::none(),
      py::arg("resolution") = d.resolution, py::arg("samples") = py::none(),
      py::arg("estimator") = py::none(), py::arg("next_event_rays") = py::none(),
      py::arg("launch_lattice") = py::none(), py::arg("straight_through") = py::none(),
      py::arg("split_threshold") = py::none(), py::arg("max_scatterings") = py::none(),
      py::arg("weave_out") = py::none(), py::arg("weave_positions") = py::none(),
      py::arg("weave_resolution") = py::none(), py::arg("sheen_resolution") = py::none(),
      py::arg("sheen_window") = py::none(), py::arg("sheen_light_resolution") = py::none(),
      py::arg("sheen_light") = py::none(), py::arg("seed") = d.seed, py::arg("threads") = d.threads,
      py::arg("yes_long") = false, py::arg("progress") = false,
      "A fabric table, as `weft bake fabric` makes it (its options are the keyword arguments, with "
      "its defaults): from a fiber (a Table, a .exr file, or a spec baked in RGB at the bake's "
      "defaults; warp_fiber, weft_fiber and thread_colours' dyes are baked into ./.weft-cache as "
      "the command bakes them; thread_colour_method 'match' (None: the default) or 'rule', as "
      "--thread-colour-method; colour: the cloth's colour, 'srgb:#RRGGBB', 'lab:L,a,b', "
      "'lab10:L,a,b' or "
      "'spectrum:FILE.csv', the fiber's dyes scaled to meet it) and a woven sample (None: the "
      "bundled poplin; a weave options file "
      "or dict), by 'summation' (the paper's), 'summation-visible' or 'raytrace'. weave_out: the "
      "ray trace's weave table is written there.");
}

}  // namespace weft::python
