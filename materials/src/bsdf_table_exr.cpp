// OpenEXR reading and writing of TabulatedBsdfTable (format described in bsdf_table.h).
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <string>

#include "exr_io.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// The table's format from the header: version, parameterization, units, kind, resolution and
// bands (returned, as the file spells them).
std::string read_table_format(const Imf::Header& h, const std::string& file,
                              TabulatedBsdfTable& table) {
  using T = TabulatedBsdfTable;
  auto string_attr = [&](const char* name) { return exr_io::string_attribute(h, file, name); };
  const int version = exr_io::int_attribute(h, file, "weft_format_version");
  if (version == 1 || version == 2)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) +
                    ": an octahedral-grid table whose bins straddle the horizon; re-bake it with "
                    "this version (format " +
                    std::to_string(T::kFormatVersion) + ")");
  if (version < T::kOldestReadableVersion || version > T::kFormatVersion)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) + "; this program reads versions " +
                    std::to_string(T::kOldestReadableVersion) + " to " +
                    std::to_string(T::kFormatVersion));
  if (string_attr("parameterization") != T::kParameterization)
    throw Error(file, "parameterization",
                "is \"" + string_attr("parameterization") + "\", expected \"" +
                    T::kParameterization + "\"");
  if (string_attr("units") != T::kUnits)
    throw Error(file, "units", "is \"" + string_attr("units") + "\", expected \"1/sr\"");
  table.kind = string_attr("kind");
  if (table.kind != "fiber" && table.kind != "fabric")
    throw Error(file, "kind", "must be \"fiber\" or \"fabric\", got \"" + table.kind + "\"");
  table.resolution = exr_io::int_attribute(h, file, "resolution");
  if (table.resolution < 1 || table.resolution > T::kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(T::kMaxResolution) + "], got " +
                    std::to_string(table.resolution));
  const std::string bands = string_attr("bands");
  if (bands == "rgb") {
    table.channels = 3;
  } else if (bands == T::kSpectralBands) {
    table.channels = kNumBands;
  } else {
    throw Error(file, "bands", "must be \"rgb\" or \"390:710:10\", got \"" + bands + "\"");
  }
  return bands;
}

// A row's sheen columns: the window bins of each of its table bin's light bins.
int sheen_columns(const HalfVectorLobe& s) {
  return s.light_bins_per_cell() * s.window_bins();
}

// The image's width: the cells' 2 R^2 columns, then the sheen's when there is one.
int image_width(const TabulatedBsdfTable& t) {
  return t.bins() + (t.sheen ? sheen_columns(*t.sheen) : 0);
}

// The data window must be the table's, and the file large enough to hold its pixels.
void check_pixel_size(const Imf::Header& h, const std::filesystem::path& path,
                      const std::string& file, const TabulatedBsdfTable& table,
                      const std::string& bands) {
  const int n = table.bins(), width = image_width(table);
  std::string why = "resolution " + std::to_string(table.resolution);
  if (table.sheen) {
    why += " and sheen window " + std::to_string(table.sheen->window);
    if (table.sheen->light_factor() > 1)
      why += " at light resolution " + std::to_string(table.sheen->light_resolution);
  }
  exr_io::check_data_window(h, file, width, n, why);
  // The pixels must be in the file before their buffer is allocated.
  exr_io::check_fits_file(path, file, "resolution",
                          double(width) * n * table.channels * sizeof(float),
                          std::to_string(table.resolution) + " and bands " + bands);
}

// The image's pixels: each row a light bin's cells, then its sheen's window bins.
std::vector<float> image_of(const TabulatedBsdfTable& t) {
  if (!t.sheen) return t.values;
  const size_t nc = static_cast<size_t>(t.channels), row = static_cast<size_t>(t.bins()) * nc;
  const size_t extra = static_cast<size_t>(sheen_columns(*t.sheen)) * nc;
  std::vector<float> out;
  out.reserve(t.values.size() + t.sheen->values.size());
  for (size_t a = 0; a < static_cast<size_t>(t.bins()); ++a) {
    out.insert(out.end(), t.values.begin() + a * row, t.values.begin() + (a + 1) * row);
    out.insert(out.end(), t.sheen->values.begin() + a * extra,
               t.sheen->values.begin() + (a + 1) * extra);
  }
  return out;
}

// The inverse of image_of into the table's values and sheen values.
void split_image(const std::vector<float>& image, TabulatedBsdfTable& t) {
  if (!t.sheen) {
    t.values = image;
    return;
  }
  const size_t nc = static_cast<size_t>(t.channels), row = static_cast<size_t>(t.bins()) * nc;
  const size_t extra = static_cast<size_t>(sheen_columns(*t.sheen)) * nc;
  t.values.clear(), t.sheen->values.clear();
  for (size_t a = 0; a < static_cast<size_t>(t.bins()); ++a) {
    const auto first = image.begin() + static_cast<std::ptrdiff_t>(a * (row + extra));
    t.values.insert(t.values.end(), first, first + static_cast<std::ptrdiff_t>(row));
    t.sheen->values.insert(t.sheen->values.end(), first + static_cast<std::ptrdiff_t>(row),
                           first + static_cast<std::ptrdiff_t>(row + extra));
  }
}

}  // namespace

void TabulatedBsdfTable::check_output_path(const std::filesystem::path& path,
                                           const std::string& field) {
  if (path.extension() != ".exr")
    throw Error(path.string(), field,
                "a table is written as OpenEXR: the name must end in .exr, not '" +
                    path.extension().string() + "'");
  std::error_code ec;
  const auto dir = std::filesystem::absolute(path, ec).parent_path();
  if (ec || !std::filesystem::is_directory(dir, ec))
    throw Error(path.string(), field, "output directory does not exist");
}

void TabulatedBsdfTable::write_exr(const std::filesystem::path& path) const {
  const std::string file = path.string();
  check_output_path(path, "");
  validate(file);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(image_width(*this), bins());
      header.insert("weft_format_version", Imf::IntAttribute(kFormatVersion));
      header.insert("cell_average", Imf::StringAttribute(kCellAverage));
      header.insert("parameterization", Imf::StringAttribute(kParameterization));
      header.insert("resolution", Imf::IntAttribute(resolution));
      header.insert("bands", Imf::StringAttribute(bands()));
      header.insert("units", Imf::StringAttribute(kUnits));
      header.insert("kind", Imf::StringAttribute(kind));
      for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
      if (surface_lobe)
        for (const auto& [key, value] : surface_lobe->attributes())
          header.insert(key, Imf::StringAttribute(value));
      if (sheen)
        for (const auto& [key, value] : sheen->attributes())
          header.insert(key, Imf::StringAttribute(value));
      exr_io::write_image(tmp, header, channel_names(), image_of(*this));
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw Error(file, "", std::string("cannot write the OpenEXR table: ") + e.what());
    }
  });
}

TabulatedBsdfTable TabulatedBsdfTable::read_exr(const std::filesystem::path& path) {
  const std::string file = path.string();
  // The largest table: 2 R^2 bins a side, and a row's sheen at most (R_l / R)^2 windows of R_h^2
  // bins more.
  const int64_t max_bins = 2 * int64_t{kMaxResolution} * kMaxResolution;
  const int64_t max_window = int64_t{HalfVectorLobe::kMaxLightFactor} *
                             HalfVectorLobe::kMaxLightFactor * HalfVectorLobe::kMaxHResolution *
                             HalfVectorLobe::kMaxHResolution;
  exr_io::check_magic(path, file);
  exr_io::check_header(path, file, max_bins + max_window, max_bins);

  TabulatedBsdfTable table;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    const std::string bands = read_table_format(h, file, table);
    const int version = exr_io::int_attribute(h, file, "weft_format_version");
    // Versions 3 and 4 knew no sheen, version 3 no lobe: their attributes there would be
    // metadata of another program's (and so for the sheen's newer attributes).
    auto attributes_of = [&](bool (*is)(const std::string&)) {
      return exr_io::string_attributes(h, [is](const std::string& n) { return !is(n); });
    };
    if (version >= 5)
      table.sheen =
          HalfVectorLobe::from_attributes(attributes_of(HalfVectorLobe::is_attribute),
                                          table.resolution, table.channels, file, version);
    check_pixel_size(h, path, file, table, bands);
    const std::vector<std::string> names = table.channel_names();
    exr_io::check_channels(h, file, names, bands);
    split_image(exr_io::read_pixels(in, file, names, image_width(table), table.bins()), table);
    table.metadata = exr_io::string_attributes(h, is_reserved_attribute);
    if (version >= 4)
      table.surface_lobe = SurfaceLobe::from_attributes(attributes_of(SurfaceLobe::is_attribute),
                                                        table.channels, file);
    if (exr_io::string_attribute(h, file, "cell_average") != kCellAverage)
      throw Error(file, "cell_average",
                  "is \"" + exr_io::string_attribute(h, file, "cell_average") +
                      "\"; this program reads \"" + kCellAverage + "\" cell averages");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("corrupt or truncated OpenEXR table: ") + e.what());
  }
  table.validate(file);
  return table;
}

}  // namespace weft