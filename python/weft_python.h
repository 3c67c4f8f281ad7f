#pragma once
// The Python module's shared pieces (docs/python.md): the Table it hands out, the progress and
// Ctrl-C of a long call, and the registration of each part of the module. The module only binds:
// the libraries do the work, and their weft::Error becomes a Python exception with its message.
#include <pybind11/pybind11.h>

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "weft/core/progress.h"
#include "weft/core/run_limits.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/materials/bsdf_table.h"
#include "weft/materials/table_reader.h"
#include "weft/materials/tabulated_bsdf.h"

namespace weft::python {

namespace py = pybind11;

// A BSDF table as Python sees it: immutable, its values shared with the numpy views it hands
// out; the renderer's sampling data made on first use.
class Table {
 public:
  explicit Table(TabulatedBsdfTable table)
      : table_(std::make_shared<const TabulatedBsdfTable>(std::move(table))) {}
  const TabulatedBsdfTable& get() const { return *table_; }
  std::shared_ptr<const TabulatedBsdfTable> shared() const { return table_; }
  // TabulatedBsdfData::prepare's result, made once (the GIL guards it).
  const TabulatedBsdf& bsdf() const;
  // The table read with its sheen (TableReader), made once (the GIL guards it); it reads table_,
  // which lives as long as this object.
  const TableReader& reader() const;

 private:
  std::shared_ptr<const TabulatedBsdfTable> table_;
  mutable std::shared_ptr<TabulatedBsdf> bsdf_;
  mutable std::shared_ptr<const TableReader> reader_;
};

// The progress of one long call, made with the GIL held; the library's callback may run on any
// thread. With 'print', a line (core/progress.h format_progress_line) on sys.stderr at most every
// 2 s and at each stage's end. On the calling thread it also checks for Ctrl-C, and asks the
// library to stop; the call then raises KeyboardInterrupt (raise_if_interrupted).
class CallProgress {
 public:
  explicit CallProgress(bool print);
  ProgressCallback callback();
  bool interrupted() const;
  // A line of the library's (a verify step), printed when 'print'; any thread.
  void note(const std::string& line) const;
  // Throws KeyboardInterrupt when the user pressed Ctrl-C during the call. Needs the GIL.
  void raise_if_interrupted() const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

// The run limits of one call (core/run_limits.h): yes_long lets work past an hour's estimate
// start (its error, in Python's words, names yes_long=True); long work is announced on stderr.
RunLimits call_limits(bool yes_long);

// A spec argument: a dict (the spec's JSON), or a file path or a preset name.
FiberSpec fiber_spec_argument(const py::object& spec);
// The JSON text of a Python dict, by Python's json (its numbers as Python writes them).
nlohmann::json dict_json(const py::dict& d, const std::string& what);
// A fiber bake, checked (memory, time: check_fiber_bake) and run without the GIL.
Table bake_fiber_checked(const FiberSpec& spec, const FiberTableBakeOptions& o, bool yes_long,
                         bool print);

void bind_table(py::module_& m);
void bind_bake_fiber(py::module_& m);
void bind_bake_fabric(py::module_& m);
void bind_verify(py::module_& m);
void bind_view(py::module_& m);

}  // namespace weft::python
