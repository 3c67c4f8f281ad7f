// weft.Table and weft.load_table: a fiber or fabric BSDF table (materials/bsdf_table.h) as numpy
// values, its header, its interpolated evaluation, the renderer's sampling and its albedos.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <optional>

#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft_python.h"

namespace weft::python {

const TabulatedBsdf& Table::bsdf() const {
  if (!bsdf_)
    bsdf_ = std::make_shared<TabulatedBsdf>(TabulatedBsdf{TabulatedBsdfData::prepare(*table_)});
  return *bsdf_;
}

const TableReader& Table::reader() const {
  if (!reader_) reader_ = std::make_shared<const TableReader>(*table_);
  return *reader_;
}

namespace {

// A direction argument: three finite numbers, not all zero; made a unit vector.
Vec3 direction(const std::vector<double>& v, const char* name) {
  if (v.size() != 3) throw Error("", name, "a direction is 3 numbers (x, y, z)");
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(n) || n == 0) throw Error("", name, "a direction must be finite and not zero");
  return {v[0] / n, v[1] / n, v[2] / n};
}

py::array_t<double> to_array(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::array_t<double> to_array(const Rgb& c) {
  return to_array(std::vector<double>{c.r, c.g, c.b});
}

// The values as a read-only view [wi_bin, wo_bin, channel] that keeps the Table alive.
py::array values_view(const py::object& self) {
  const TabulatedBsdfTable& t = self.cast<const Table&>().get();
  const auto b = static_cast<py::ssize_t>(t.bins()), c = static_cast<py::ssize_t>(t.channels);
  const auto f = static_cast<py::ssize_t>(sizeof(float));
  py::array_t<float> a({b, b, c}, {b * c * f, c * f, f}, t.values.data(), self);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

// A table from numpy values [2R^2, 2R^2, channels], checked like a file's (validate) with the
// argument's names in the errors.
Table from_array(const py::array& values, const std::string& kind,
                 const std::optional<std::string>& bands,
                 const std::map<std::string, std::string>& metadata) {
  if (values.ndim() != 3)
    throw Error("", "values",
                "must have 3 axes [wi_bin, wo_bin, channel], got " + std::to_string(values.ndim()));
  const auto bins = values.shape(0), channels = values.shape(2);
  const int r = static_cast<int>(std::lround(std::sqrt(static_cast<double>(bins) / 2)));
  if (values.shape(1) != bins || 2 * static_cast<py::ssize_t>(r) * r != bins || r < 1)
    throw Error("", "values",
                "shape must be [2R^2, 2R^2, channels] for a resolution R, got [" +
                    std::to_string(bins) + ", " + std::to_string(values.shape(1)) + ", " +
                    std::to_string(channels) + "]");
  if (channels != 3 && channels != kNumBands)
    throw Error("", "values",
                "must have 3 (RGB) or 33 (390..710 nm) channels, got " + std::to_string(channels));
  TabulatedBsdfTable t;
  t.resolution = r;
  t.channels = static_cast<int>(channels);
  t.kind = kind;
  t.metadata = metadata;
  if (bands && *bands != t.bands())
    throw Error("", "bands",
                "'" + *bands + "' does not match the values' " + std::to_string(channels) +
                    " channels ('" + t.bands() + "')");
  const auto c = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!c) throw Error("", "values", "must be numbers");
  t.values.assign(c.data(), c.data() + c.size());
  t.validate("");
  return Table(std::move(t));
}

py::dict albedo_dict(const TabulatedBsdfTable::DirectionalAlbedo& a) {
  py::dict d;
  d["reflectance"] = to_array(a.reflectance);
  d["transmittance"] = to_array(a.transmittance);
  std::vector<double> total(a.reflectance.size());
  for (size_t c = 0; c < total.size(); ++c) total[c] = a.total(static_cast<int>(c));
  d["total"] = to_array(total);
  return d;
}

py::object sample(const Table& t, const std::vector<double>& wo, double u1, double u2,
                  double u_lobe) {
  for (double u : {u1, u2, u_lobe})
    if (!(u >= 0 && u < 1)) throw Error("", "u", "random numbers must be in [0, 1)");
  const auto s = t.bsdf().sample(direction(wo, "wo"), Vec2{u1, u2}, u_lobe);
  if (!s) return py::none();
  py::dict d;
  d["wi"] = to_array(std::vector<double>{s->wi.x, s->wi.y, s->wi.z});
  d["weight"] = to_array(s->weight);
  d["pdf"] = s->pdf;
  return d;
}

std::optional<py::array_t<double>> wavelengths(const TabulatedBsdfTable& t) {
  if (t.channels != kNumBands) return std::nullopt;
  std::vector<double> w;
  for (int b = 0; b < kNumBands; ++b) w.push_back(band_wavelength_nm(b));
  return to_array(w);
}

}  // namespace

void bind_table(py::module_& m) {
  py::class_<Table>(m, "Table",
                    "A fiber or fabric BSDF table: cosine-weighted cell averages of f (1/sr) over "
                    "pairs of direction bins (docs/fiber-bsdf.md).")
      .def_property_readonly("values", &values_view,
                             "read-only float32 view [wi_bin, wo_bin, channel], 2R^2 bins each")
      .def_property_readonly("resolution", [](const Table& t) { return t.get().resolution; })
      .def_property_readonly("channels", [](const Table& t) { return t.get().channels; })
      .def_property_readonly("kind", [](const Table& t) { return t.get().kind; })
      .def_property_readonly(
          "bands", [](const Table& t) { return t.get().bands(); }, "'rgb' or '390:710:10'")
      .def_property_readonly("channel_names",
                             [](const Table& t) { return t.get().channel_names(); })
      .def_property_readonly(
          "wavelengths", [](const Table& t) { return wavelengths(t.get()); },
          "band centres in nm (None for an RGB table)")
      .def_property_readonly("metadata", [](const Table& t) { return t.get().metadata; })
      .def_property_readonly(
          "surface_lobe",
          [](const Table& t) -> std::optional<std::map<std::string, std::string>> {
            if (!t.get().surface_lobe) return std::nullopt;
            return t.get().surface_lobe->attributes();
          },
          "the analytic surface lobe the cells include, as the file names it (None: none; "
          "docs/fiber-bsdf.md)")
      .def_property_readonly(
          "sheen",
          [](const Table& t) -> std::optional<std::map<std::string, std::string>> {
            if (!t.get().sheen) return std::nullopt;
            return t.get().sheen->attributes();
          },
          "the sheen over half vectors the cells include, as the file names it (None: none; "
          "docs/fabric-bsdf.md)")
      .def_property_readonly("checksum", [](const Table& t) { return t.get().checksum(); })
      .def(
          "bin_of",
          [](const Table& t, const std::vector<double>& w) {
            return t.get().grid().bin_of(direction(w, "w"));
          },
          py::arg("w"), "The bin (index of values' first two axes) holding direction w")
      .def(
          "bin_center",
          [](const Table& t, int bin) {
            if (bin < 0 || bin >= t.get().bins())
              throw Error("", "bin", "must be in [0, " + std::to_string(t.get().bins()) + ")");
            const Vec3 c = t.get().grid().bin_center(bin);
            return to_array(std::vector<double>{c.x, c.y, c.z});
          },
          py::arg("bin"), "The unit direction at the centre of a bin")
      .def(
          "save",
          [](const Table& t, const std::filesystem::path& path) {
            TabulatedBsdfTable::check_output_path(path, "path");
            t.get().write_exr(path);
          },
          py::arg("path"), "Writes the OpenEXR table (bit-exact round trip).")
      .def(
          "eval",
          [](const Table& t, const std::vector<double>& wo, const std::vector<double>& wi) {
            std::vector<double> out(static_cast<size_t>(t.get().channels));
            t.reader().eval(direction(wo, "wo"), direction(wi, "wi"), out);
            return to_array(out);
          },
          py::arg("wo"), py::arg("wi"),
          "f(wo, wi) per channel, as the renderer reads the table: interpolated, plus its sheen "
          "when it holds one (local frame: x the fiber or warp axis, z the normal)")
      .def("sample", &sample, py::arg("wo"), py::arg("u1"), py::arg("u2"), py::arg("u_lobe") = 0.5,
           "The renderer's sampling for wo (RGB): dict wi, weight = f |cos| / pdf, pdf; or None")
      .def(
          "pdf",
          [](const Table& t, const std::vector<double>& wo, const std::vector<double>& wi) {
            return t.bsdf().pdf(direction(wo, "wo"), direction(wi, "wi"));
          },
          py::arg("wo"), py::arg("wi"))
      .def(
          "albedo",
          [](const Table& t, const std::vector<double>& wi) {
            const TabulatedBsdfTable& tb = t.get();
            return albedo_dict(tb.directional_albedo(tb.grid().bin_of(direction(wi, "wi"))));
          },
          py::arg("wi"),
          "Where light from wi's bin goes, per channel: reflectance, transmittance, total")
      .def("total_albedo", [](const Table& t) { return to_array(t.get().total_albedo()); })
      .def_static(
          "from_array", &from_array, py::arg("values"), py::arg("kind") = "fiber",
          py::arg("bands") = py::none(), py::arg("metadata") = std::map<std::string, std::string>{},
          "A table from numpy values [2R^2, 2R^2, channels] (3 or 33), each finite and >= 0")
      .def("__repr__", [](const Table& t) {
        const TabulatedBsdfTable& tb = t.get();
        return "<weft.Table " + tb.kind + " R=" + std::to_string(tb.resolution) + " " + tb.bands() +
               ">";
      });
  m.def(
      "load_table",
      [](const std::filesystem::path& path) { return Table(TabulatedBsdfTable::read_exr(path)); },
      py::arg("path"), "Reads and checks an OpenEXR table (weft bake fiber / fabric)");
}

}  // namespace weft::python
