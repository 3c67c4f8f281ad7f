#include "weft/core/colour_target.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/params.h"

namespace weft {

namespace {

constexpr const char* kColourSpecForms =
    "srgb:#RRGGBB, lab:L,a,b, lab10:L,a,b or spectrum:FILE.csv";
// How far past its first or last row a spectrum is held flat.
constexpr double kSpectrumHoldNm = 15;

ColourTarget srgb_target(const std::string& spec, const std::string& hex,
                         const std::string& field) {
  const std::string digits = !hex.empty() && hex[0] == '#' ? hex.substr(1) : hex;
  if (digits.size() != 6 || digits.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw Error("", field, "srgb: takes six hex digits, e.g. srgb:#8c1c24; got '" + hex + "'");
  Rgb linear;
  for (int k = 0; k < 3; ++k)
    linear[k] = srgb_gamma_to_linear(std::stoi(digits.substr(2 * k, 2), nullptr, 16) / 255.0);
  return linear_srgb_target(linear, spec);
}

ColourTarget lab_target(const std::string& spec, const std::string& values, Observer observer,
                        const std::string& field) {
  std::vector<double> v;
  std::istringstream in(values);
  std::string cell;
  while (std::getline(in, cell, ',')) {
    const auto x = finite_number(cell);
    if (!x) throw Error("", field, "'" + cell + "' in '" + spec + "' is not a finite number");
    v.push_back(*x);
  }
  if (v.size() != 3)
    throw Error("", field, "give L*, a* and b*, e.g. lab:45,60,30; got '" + spec + "'");
  if (v[0] < 0 || v[0] > 100)
    throw Error("", field, "L* must be in [0, 100], got " + ParamReader::fmt(v[0]));
  if (std::abs(v[1]) > 200 || std::abs(v[2]) > 200)
    throw Error("", field, "a* and b* must be in [-200, 200] (beyond any surface colour)");
  ColourTarget t;
  t.spec = spec;
  t.kind = ColourTarget::Kind::kLab;
  t.observer = observer;
  t.lab = {v[0], v[1], v[2]};
  return t;
}

struct SpectrumRow {
  double nm = 0, reflectance = 0;
};

// "nm,reflectance" (separated by a comma, semicolon or tab), or nothing.
std::optional<SpectrumRow> spectrum_row(std::string line) {
  for (char& c : line)
    if (c == ';' || c == '\t') c = ',';
  const size_t comma = line.find(',');
  if (comma == std::string::npos) return std::nullopt;
  const auto nm = finite_number(line.substr(0, comma));
  const auto r = finite_number(line.substr(comma + 1));
  if (!nm || !r) return std::nullopt;
  return SpectrumRow{*nm, *r};
}

// The rows of a spectrum file, checked: two numbers each, increasing wavelengths, reflectances in
// [0, kMaxSpectrumReflectance].
std::vector<SpectrumRow> spectrum_rows(const std::string& file, const std::string& field) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (ec) throw Error(file, field, "cannot read the spectrum: " + ec.message());
  if (bytes > kMaxSpectrumFileBytes)
    throw Error(file, field,
                "the spectrum file has " + std::to_string(bytes) +
                    " bytes; a spectrophotometer's export has a few kB (at most " +
                    std::to_string(kMaxSpectrumFileBytes) + ")");
  std::ifstream in(file);
  if (!in) throw Error(file, field, "cannot open the spectrum file");
  std::vector<SpectrumRow> rows;
  std::string line;
  for (size_t line_no = 1; std::getline(in, line); ++line_no) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = "line " + std::to_string(line_no);
    const std::optional<SpectrumRow> row = spectrum_row(line);
    if (!row) {
      if (rows.empty() && !finite_number(line.substr(0, line.find(',')))) continue;  // a header
      throw Error(file, field, where + ": want 'wavelength_nm,reflectance', got '" + line + "'");
    }
    const double nm = row->nm, r = row->reflectance;
    if (rows.size() == kMaxSpectrumRows)
      throw Error(file, field, "more than " + std::to_string(kMaxSpectrumRows) + " rows");
    if (!rows.empty() && nm <= rows.back().nm)
      throw Error(file, field, where + ": wavelengths must increase");
    if (r < 0 || r > kMaxSpectrumReflectance)
      throw Error(file, field,
                  where + ": reflectance " + ParamReader::fmt(r) + " is outside [0, " +
                      ParamReader::fmt(kMaxSpectrumReflectance) +
                      "] (a percentage? give fractions: 45 % is 0.45)");
    rows.push_back(*row);
  }
  if (rows.size() < 2 || rows.front().nm > kSpectrumMinStartNm ||
      rows.back().nm < kSpectrumMinEndNm)
    throw Error(file, field,
                "the spectrum must cover " + ParamReader::fmt(kSpectrumMinStartNm) + "-" +
                    ParamReader::fmt(kSpectrumMinEndNm) + " nm; it has " +
                    std::to_string(rows.size()) + " rows" +
                    (rows.empty() ? std::string()
                                  : " from " + ParamReader::fmt(rows.front().nm) + " to " +
                                        ParamReader::fmt(rows.back().nm) + " nm"));
  return rows;
}

// The rows' reflectance at 'nm', linear between rows, flat past the ends.
double spectrum_at(const std::vector<SpectrumRow>& rows, double nm) {
  if (nm <= rows.front().nm) return rows.front().reflectance;
  if (nm >= rows.back().nm) return rows.back().reflectance;
  size_t k = 1;
  while (rows[k].nm < nm) ++k;
  const double t = (nm - rows[k - 1].nm) / (rows[k].nm - rows[k - 1].nm);
  return rows[k - 1].reflectance + t * (rows[k].reflectance - rows[k - 1].reflectance);
}

}  // namespace

Spectrum read_reflectance_csv(const std::string& file, const std::string& field) {
  const std::vector<SpectrumRow> rows = spectrum_rows(file, field);
  static_assert(kSpectrumMinStartNm - (kFirstBandNm - kBandStepNm / 2) <= kSpectrumHoldNm &&
                (kFirstBandNm + kBandStepNm * (kNumBands - 0.5)) - kSpectrumMinEndNm <=
                    kSpectrumHoldNm);
  Spectrum s{};
  for (int b = 0; b < kNumBands; ++b) {
    s[b] = band_mean_1nm(b, [&](int nm) { return spectrum_at(rows, nm); });
  }
  return s;
}

ColourTarget linear_srgb_target(const Rgb& linear, const std::string& spec) {
  ColourTarget t;
  t.spec = spec;
  t.kind = ColourTarget::Kind::kSrgb;
  t.lab = linear_srgb_to_lab(linear);
  return t;
}

ColourTarget parse_colour_target(const std::string& spec, const std::string& field) {
  const size_t colon = spec.find(':');
  const std::string form = spec.substr(0, colon),
                    rest = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (colon == std::string::npos || rest.empty())
    throw Error("", field,
                std::string("give a colour as ") + kColourSpecForms + "; got '" + spec + "'");
  if (form == "srgb") return srgb_target(spec, rest, field);
  if (form == "lab") return lab_target(spec, rest, Observer::kCie1931TwoDegree, field);
  if (form == "lab10") return lab_target(spec, rest, Observer::kCie1964TenDegree, field);
  if (form != "spectrum")
    throw Error("", field, "unknown colour form '" + form + "': give " + kColourSpecForms);
  ColourTarget t;
  t.spec = spec;
  t.kind = ColourTarget::Kind::kSpectrum;
  t.observer = Observer::kCie1964TenDegree;  // a spectrophotometer's usual report
  t.file = rest;
  t.reflectance = read_reflectance_csv(rest, field);
  t.lab = reflectance_to_lab(*t.reflectance, t.observer);
  return t;
}

std::string ColourTarget::key() const {
  std::string k = spec + "," + ParamReader::fmt(lab.l) + "," + ParamReader::fmt(lab.a) + "," +
                  ParamReader::fmt(lab.b);
  if (reflectance)
    for (double v : *reflectance) k += "," + ParamReader::fmt(v);
  return hex64(fnv1a64(k));
}

Lab ColourTarget::lab_of(const Spectrum& r) const {
  if (kind == Kind::kSrgb)
    return linear_srgb_to_lab(bands_to_linear_srgb([&](int b) { return r[b]; }));
  return reflectance_to_lab(r, observer);
}

}  // namespace weft
