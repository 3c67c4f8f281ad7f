// The weave table's validation and OpenEXR format (weave_table.h).
#include "weft/materials/weave_table.h"

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#include "exr_io.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/params.h"
#include "weft/core/spectrum.h"
#include "weft/materials/bsdf_table.h"

namespace weft {
namespace {

// The positive integer 'text' is (all of it), if any.
std::optional<int> positive_int(std::string_view text) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < 1) return std::nullopt;
  return v;
}

// Shortest text that reads back as the same double.
std::string round_trip(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

// "UxV" -> positions_u, positions_v.
void read_positions(const Imf::Header& h, const std::string& file, WeaveTable& t) {
  const std::string text = exr_io::string_attribute(h, file, "positions");
  const size_t x = text.find('x');
  const auto u = positive_int(std::string_view(text).substr(0, x));
  const auto v =
      x == std::string::npos ? std::nullopt : positive_int(std::string_view(text).substr(x + 1));
  if (!u || !v || *u > WeaveTable::kMaxPositions || *v > WeaveTable::kMaxPositions)
    throw Error(file, "positions",
                "must be \"UxV\" with U and V in [1, " + std::to_string(WeaveTable::kMaxPositions) +
                    "], got \"" + text + "\"");
  t.positions_u = *u;
  t.positions_v = *v;
}

// "U V" metres -> repeat_u_m, repeat_v_m.
void read_repeat(const Imf::Header& h, const std::string& file, WeaveTable& t) {
  const std::string text = exr_io::string_attribute(h, file, "repeat_m");
  std::istringstream in(text);
  std::string a, b, extra;
  in >> a >> b;
  const auto u = finite_number(a), v = finite_number(b);
  if (!u || !v || *u <= 0 || *v <= 0 || (in >> extra))
    throw Error(file, "repeat_m",
                "must be two positive numbers (metres along u and v), got \"" + text + "\"");
  t.repeat_u_m = *u;
  t.repeat_v_m = *v;
}

// Kind (first: a fabric table named as a weave is told so), version, resolution, positions,
// repeat and bands from the header; returns the bands as the file spells them.
std::string read_weave_format(const Imf::Header& h, const std::string& file, WeaveTable& t) {
  const std::string kind = exr_io::string_attribute(h, file, "kind");
  if (kind != WeaveTable::kKind)
    throw Error(file, "kind",
                "is \"" + kind + "\", expected \"" + WeaveTable::kKind +
                    "\" (a weave table, as bake fabric --weave-out writes)");
  const int version = exr_io::int_attribute(h, file, "weft_format_version");
  if (version != WeaveTable::kFormatVersion)
    throw Error(file, "weft_format_version",
                "is " + std::to_string(version) + "; this program reads version " +
                    std::to_string(WeaveTable::kFormatVersion));
  t.resolution = exr_io::int_attribute(h, file, "resolution");
  if (t.resolution < 1 || t.resolution > WeaveTable::kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(WeaveTable::kMaxResolution) + "], got " +
                    std::to_string(t.resolution));
  read_positions(h, file, t);
  read_repeat(h, file, t);
  const std::string bands = exr_io::string_attribute(h, file, "bands");
  if (bands == "rgb") {
    t.channels = 3;
  } else if (bands == TabulatedBsdfTable::kSpectralBands) {
    t.channels = kNumBands;
  } else {
    throw Error(file, "bands", "must be \"rgb\" or \"390:710:10\", got \"" + bands + "\"");
  }
  return bands;
}

// Number of values the sizes call for (no overflow: every factor is bounded).
size_t expected_values(const WeaveTable& t) {
  return static_cast<size_t>(t.positions()) * static_cast<size_t>(t.bins()) *
         static_cast<size_t>(t.bins()) * static_cast<size_t>(t.channels);
}

void check_sizes(const WeaveTable& t, const std::string& file) {
  if (t.resolution < 1 || t.resolution > WeaveTable::kMaxResolution)
    throw Error(file, "resolution",
                "must lie in [1, " + std::to_string(WeaveTable::kMaxResolution) + "], got " +
                    std::to_string(t.resolution));
  if (t.channels != 3 && t.channels != kNumBands)
    throw Error(file, "bands",
                "need 3 (RGB) or 33 (390..710 nm) channels, got " + std::to_string(t.channels));
  const int max_p = WeaveTable::kMaxPositions;
  if (t.positions_u < 1 || t.positions_u > max_p || t.positions_v < 1 || t.positions_v > max_p)
    throw Error(file, "positions",
                "must be in [1, " + std::to_string(max_p) + "] per side, got " +
                    std::to_string(t.positions_u) + "x" + std::to_string(t.positions_v));
  if (!(std::isfinite(t.repeat_u_m) && t.repeat_u_m > 0 && std::isfinite(t.repeat_v_m) &&
        t.repeat_v_m > 0))
    throw Error(file, "repeat_m",
                "must be finite and > 0 metres, got " + round_trip(t.repeat_u_m) + " " +
                    round_trip(t.repeat_v_m));
  if (expected_values(t) > WeaveTable::kMaxValues)
    throw Error(file, "positions",
                std::to_string(expected_values(t)) + " values (positions x bins^2 x channels), " +
                    "more than the " + std::to_string(WeaveTable::kMaxValues) + " allowed");
}

}  // namespace

std::string WeaveTable::bands() const {
  return channels == kNumBands ? std::string(TabulatedBsdfTable::kSpectralBands)
                               : std::string("rgb");
}

std::string WeaveTable::checksum() const {
  return exr_io::checksum(modulation);
}

bool WeaveTable::is_reserved_attribute(const std::string& name) {
  return name == "positions" || name == "repeat_m" ||
         TabulatedBsdfTable::is_reserved_attribute(name);
}

void WeaveTable::validate(const std::string& file) const {
  check_sizes(*this, file);
  if (modulation.size() != expected_values(*this))
    throw Error(file, "modulation",
                "holds " + std::to_string(modulation.size()) + " numbers, expected " +
                    std::to_string(expected_values(*this)));
  for (const auto& [key, value] : metadata)
    if (key.empty() || is_reserved_attribute(key))
      throw Error(file, "metadata." + key, "name is reserved by the weave table format");
  const size_t n = static_cast<size_t>(bins()), nc = static_cast<size_t>(channels);
  for (size_t i = 0; i < modulation.size(); ++i) {
    const float v = modulation[i];
    if (std::isfinite(v) && v >= 0) continue;
    const size_t cell = i / nc;
    throw Error(file,
                "modulation[pos " + std::to_string(cell / (n * n)) + "][wi " +
                    std::to_string(cell / n % n) + "][wo " + std::to_string(cell % n) + "][" +
                    exr_io::channel_names(channels)[i % nc] + "]",
                std::isfinite(v) ? "is negative (" + std::to_string(v) + ")" : "is not finite");
  }
}

void WeaveTable::write_exr(const std::filesystem::path& path) const {
  const std::string file = path.string();
  TabulatedBsdfTable::check_output_path(path, "");
  validate(file);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(bins(), positions() * bins());
      header.insert("weft_format_version", Imf::IntAttribute(kFormatVersion));
      header.insert("kind", Imf::StringAttribute(kKind));
      header.insert("resolution", Imf::IntAttribute(resolution));
      header.insert("positions", Imf::StringAttribute(std::to_string(positions_u) + "x" +
                                                      std::to_string(positions_v)));
      header.insert("repeat_m",
                    Imf::StringAttribute(round_trip(repeat_u_m) + " " + round_trip(repeat_v_m)));
      header.insert("bands", Imf::StringAttribute(bands()));
      for (const auto& [key, value] : metadata) header.insert(key, Imf::StringAttribute(value));
      exr_io::write_image(tmp, header, exr_io::channel_names(channels), modulation);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw Error(file, "", std::string("cannot write the OpenEXR weave table: ") + e.what());
    }
  });
}

WeaveTable WeaveTable::read_exr(const std::filesystem::path& path) {
  const std::string file = path.string();
  const int64_t max_bins = 2 * int64_t{kMaxResolution} * kMaxResolution;
  exr_io::check_magic(path, file);
  exr_io::check_header(path, file, max_bins, max_bins * kMaxPositions * kMaxPositions);
  WeaveTable t;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    const std::string bands = read_weave_format(h, file, t);
    check_sizes(t, file);
    exr_io::check_data_window(h, file, t.bins(), t.positions() * t.bins(),
                              "resolution " + std::to_string(t.resolution) + " and positions " +
                                  std::to_string(t.positions_u) + "x" +
                                  std::to_string(t.positions_v));
    // The pixels must be in the file before their buffer is allocated.
    exr_io::check_fits_file(path, file, "positions", double(expected_values(t)) * sizeof(float),
                            "resolution " + std::to_string(t.resolution) + ", positions " +
                                std::to_string(t.positions_u) + "x" +
                                std::to_string(t.positions_v) + " and bands " + bands);
    const auto names = exr_io::channel_names(t.channels);
    exr_io::check_channels(h, file, names, bands);
    t.modulation = exr_io::read_pixels(in, file, names, t.bins(), t.positions() * t.bins());
    t.metadata = exr_io::string_attributes(h, is_reserved_attribute);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(file, "", std::string("corrupt or truncated OpenEXR weave table: ") + e.what());
  }
  t.validate(file);
  return t;
}

}  // namespace weft
