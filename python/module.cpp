// `import weft`: the Python module (docs/python.md). Registers its parts, turns weft::Error into
// weft.Error (a ValueError) with the library's message, and tells the libraries where an
// installed module's bundled data lies.
#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <regex>

#include "weft/core/error.h"
#include "weft/core/install_paths.h"
#include "weft/fiber/fiber_spec.h"
#include "weft_python.h"

namespace weft::python {
namespace {

// This module's own file (python3 is the executable, which says nothing about Weft's prefix).
std::filesystem::path module_file() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&module_file), &info) == 0 || !info.dli_fname) return {};
  std::error_code ec;
  const auto p = std::filesystem::canonical(info.dli_fname, ec);
  return ec ? std::filesystem::path() : p;
}

// A library message in Python's words: the command line's options ("--fit-params") are the
// keyword arguments ("fit_params"); "add --yes-long" is yes_long=True.
std::string python_words(std::string message) {
  const std::string yes_long = "add --yes-long";
  for (size_t at; (at = message.find(yes_long)) != std::string::npos;)
    message.replace(at, yes_long.size(), "pass yes_long=True");
  static const std::regex option("(^|[ '(])--([a-z][a-z0-9]*(-[a-z0-9]+)*)");
  std::string out;
  auto begin = message.cbegin();
  for (std::smatch mt; std::regex_search(begin, message.cend(), mt, option);
       begin = mt.suffix().first) {
    std::string name = mt[2].str();
    std::replace(name.begin(), name.end(), '-', '_');
    out.append(mt.prefix().first, mt.prefix().second).append(mt[1].str()).append(name);
  }
  return out.append(begin, message.cend());
}

}  // namespace
}  // namespace weft::python

PYBIND11_MODULE(weft, m) {
  using namespace weft::python;
  m.doc() =
      "Weft from Python: fiber and fabric BSDF tables, and weft verify (docs/python.md). The "
      "libraries do the work; their errors are weft.Error naming the file and field.";
  m.attr("__version__") = WEFT_VERSION;
  // Installed: <prefix>/share/weft lies WEFT_PYTHON_DATA_FROM_MODULE from the module's folder. In
  // the build tree there is none there, and the source tree it was built from is used.
  const std::filesystem::path self = module_file();
  if (!self.empty())
    weft::set_installed_data_root(self.parent_path() / WEFT_PYTHON_DATA_FROM_MODULE);
  static py::exception<weft::Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const weft::Error& e) {
      error(python_words(e.what()).c_str());
    }
  });
  m.def("presets", &weft::fiber_preset_names, "The bundled fiber presets' names.");
  bind_table(m);
  bind_bake_fiber(m);
  bind_bake_fabric(m);
  bind_verify(m);
  bind_view(m);
}
