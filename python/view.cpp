// weft.view: `weft view`'s page of a table from Python (exchange/view_request.h, the same request,
// plan and run); returns what the run reports instead of printing it.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

#include "weft/exchange/view_request.h"
#include "weft_python.h"

namespace weft::python {

void bind_view(py::module_& m) {
  m.def(
      "view",
      [](const std::filesystem::path& table, const std::filesystem::path& output,
         const std::optional<std::string>& name) {
        ViewRequest r;
        r.table = table.string();
        r.output = output.string();
        if (name) r.name = *name;
        const ViewPlan plan = plan_view(r);
        ExportReport report;
        {
          py::gil_scoped_release release;
          report = run_view(plan);
        }
        py::dict figures;
        for (const auto& [key, value] : report.figures) figures[py::str(key)] = value;
        py::dict out;
        out["format"] = report.format;
        out["dropped"] = report.dropped;
        out["notes"] = report.notes;
        out["figures"] = figures;
        out["warnings"] = plan.warnings;
        out["output"] = output;
        return out;
      },
      py::arg("table"), py::arg("output"), py::kw_only(), py::arg("name") = py::none(),
      "`weft view TABLE -o OUTPUT`: one offline .html page of a table (docs/exchange.md), its "
      "in-plane curves with the incidence chosen on the page and, for a fabric table, the glTF "
      "material fitted to it in 3-D. Returns what the page holds (format, dropped, notes, "
      "figures) and the warnings the plan gave.");
}

}  // namespace weft::python
