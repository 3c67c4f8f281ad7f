#include "weft/fiber/dye.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "embedded_json.h"
#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft {

namespace {

// One row of a dye's tabulated spectrum.
struct DyeSpectrumRow {
  double nm = 0, epsilon = 0;
};

// The rows of the file's spectrum key, checked: [nm, epsilon] pairs with wavelengths increasing
// in [kMinDyeSpectrumNm, kMaxDyeSpectrumNm] and epsilon finite in [0, kMaxDyeEpsilon].
std::vector<DyeSpectrumRow> read_dye_spectrum_rows(ParamReader& p, const std::string& key) {
  const nlohmann::json& rows = p.at(key);
  const std::string field = p.field(key);
  if (!rows.is_array() || rows.size() < 2 || rows.size() > kMaxDyeSpectrumRows)
    throw Error(p.file(), field,
                "must be an array of 2 to " + std::to_string(kMaxDyeSpectrumRows) +
                    " rows [wavelength_nm, epsilon_per_M_per_cm]");
  std::vector<DyeSpectrumRow> out;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string row = field + "[" + std::to_string(i) + "]";
    if (!rows[i].is_array() || rows[i].size() != 2)
      throw Error(p.file(), row, "must be a pair [wavelength_nm, epsilon_per_M_per_cm]");
    const double nm = p.check_number(rows[i][0], row + "[0]", kMinDyeSpectrumNm, kMaxDyeSpectrumNm);
    const double epsilon = p.check_number(rows[i][1], row + "[1]", 0, kMaxDyeEpsilon);
    if (!out.empty() && nm <= out.back().nm)
      throw Error(p.file(), row + "[0]",
                  "wavelengths must increase: " + ParamReader::fmt(nm) + " nm follows " +
                      ParamReader::fmt(out.back().nm) + " nm");
    out.push_back({nm, epsilon});
  }
  return out;
}

// A table stopping inside the bands must stop where its absorption has died away, since epsilon
// is taken as 0 past its ends.
void check_dye_spectrum_ends(const std::vector<DyeSpectrumRow>& rows, const std::string& file,
                             const std::string& field) {
  double peak = 0;
  for (const auto& r : rows) peak = std::max(peak, r.epsilon);
  if (peak <= 0) throw Error(file, field, "has no absorption (every epsilon is 0)");
  const double first_nm = band_wavelength_nm(0) - kBandStepNm / 2;
  const double last_nm = band_wavelength_nm(kNumBands - 1) + kBandStepNm / 2;
  for (const DyeSpectrumRow& end : {rows.front(), rows.back()}) {
    if (end.nm <= first_nm || end.nm >= last_nm) continue;
    if (end.epsilon > kDyeSpectrumEndFraction * peak)
      throw Error(file, field,
                  "stops at " + ParamReader::fmt(end.nm) + " nm, inside " +
                      ParamReader::fmt(first_nm) + "-" + ParamReader::fmt(last_nm) +
                      " nm, where epsilon is still " + ParamReader::fmt(end.epsilon) +
                      " (more than " + ParamReader::fmt(100 * kDyeSpectrumEndFraction) +
                      " % of its peak " + ParamReader::fmt(peak) +
                      "); give the spectrum on to where the absorption has died away");
  }
}

// Mean over [lo_nm, hi_nm] of the rows joined linearly, 0 past the table's ends: the exact
// integral of the polyline, which for a 1 nm table is the trapezoid rule of core's band averages.
double dye_table_mean(const std::vector<DyeSpectrumRow>& rows, double lo_nm, double hi_nm) {
  double integral = 0;
  for (size_t k = 1; k < rows.size(); ++k) {
    const DyeSpectrumRow &a = rows[k - 1], &b = rows[k];
    const double u = std::max(a.nm, lo_nm), v = std::min(b.nm, hi_nm);
    if (v <= u) continue;
    auto at = [&](double nm) {
      return a.epsilon + (b.epsilon - a.epsilon) * (nm - a.nm) / (b.nm - a.nm);
    };
    integral += (v - u) * (at(u) + at(v)) / 2;
  }
  return integral / (hi_nm - lo_nm);
}

Spectrum epsilon_from_table(const std::vector<DyeSpectrumRow>& rows) {
  Spectrum e{};
  for (int b = 0; b < kNumBands; ++b)
    e[b] = dye_table_mean(rows, band_wavelength_nm(b) - kBandStepNm / 2,
                          band_wavelength_nm(b) + kBandStepNm / 2);
  return e;
}

// Sums the file's Gaussian bands (dye.h) at the band centres.
Spectrum epsilon_from_gaussian_bands(ParamReader& p) {
  const nlohmann::json& bands = p.at("bands");
  if (!bands.is_array() || bands.empty() || bands.size() > kMaxDyeGaussianBands)
    throw Error(
        p.file(), p.field("bands"),
        "must be an array of 1 to " + std::to_string(kMaxDyeGaussianBands) + " absorption bands");
  Spectrum e{};
  for (size_t i = 0; i < bands.size(); ++i) {
    ParamReader b(bands[i], p.file(), "bands[" + std::to_string(i) + "]");
    // Ultraviolet to near-infrared bands; an electronic band is a few hundred to some thousands
    // of wavenumbers wide.
    const double lambda_max_nm = b.number("lambda_max_nm", 200, 1200);
    const double epsilon_max = b.number("epsilon_max_per_M_per_cm", 1e-300, kMaxDyeEpsilon);
    const double fwhm_per_cm = b.number("fwhm_per_cm", 100, 20000);
    b.finish();
    const double nu_max = 1e7 / lambda_max_nm;
    for (int k = 0; k < kNumBands; ++k) {
      const double nu = 1e7 / band_wavelength_nm(k);
      e[k] += epsilon_max * std::exp(-4 * std::numbers::ln2 * (nu - nu_max) * (nu - nu_max) /
                                     (fwhm_per_cm * fwhm_per_cm));
    }
  }
  return e;
}

}  // namespace

DyeSpectrum parse_dye_spectrum(const std::string& json_text, const std::string& file) {
  const nlohmann::json root = parse_json(json_text, file);
  ParamReader p(root, file, "");
  DyeSpectrum d;
  d.name = p.string("name");
  d.colour_index = p.string("colour_index");
  for (const char* key : {"use", "formula", "solvent", "source"}) (void)p.string(key);
  d.molar_mass_g_per_mol = p.number("molar_mass_g_per_mol", 1, 1e5);
  if (p.has("dye_class")) {
    d.dye_class = p.string("dye_class");
    if (d.dye_class.empty()) throw Error(file, "dye_class", "must not be empty when given");
  }
  const bool table = p.has(kDyeSpectrumKey), bands = p.has("bands");
  if (table == bands)
    throw Error(file, table ? "bands" : kDyeSpectrumKey,
                std::string("give the absorption either as a tabulated spectrum (") +
                    kDyeSpectrumKey + ") or as Gaussian bands (bands), " +
                    (table ? "not both" : "neither is given"));
  if (table) {
    const std::vector<DyeSpectrumRow> rows = read_dye_spectrum_rows(p, kDyeSpectrumKey);
    check_dye_spectrum_ends(rows, file, kDyeSpectrumKey);
    d.epsilon_per_M_per_cm = epsilon_from_table(rows);
    d.tabulated = true;
  } else {
    d.epsilon_per_M_per_cm = epsilon_from_gaussian_bands(p);
  }
  p.finish();
  return d;
}

double dye_peak_nm(const DyeSpectrum& dye) {
  const Spectrum& e = dye.epsilon_per_M_per_cm;
  return band_wavelength_nm(static_cast<int>(std::max_element(e.begin(), e.end()) - e.begin()));
}

DyeHue dye_hue(const DyeSpectrum& dye) {
  const double peak_nm = dye_peak_nm(dye);
  return peak_nm < 470 ? DyeHue::kYellow : peak_nm < 570 ? DyeHue::kRed : DyeHue::kBlue;
}

std::vector<std::string> bundled_dye_names() {
  std::vector<std::string> names;
  for (int i = 0; i < detail::kNumFiberDyes; ++i) names.emplace_back(detail::kFiberDyes[i].name);
  return names;
}

const DyeSpectrum& bundled_dye(const std::string& name, const std::string& file,
                               const std::string& field) {
  // Parsed once from immutable compiled-in text.
  static const std::vector<DyeSpectrum> dyes = [] {
    std::vector<DyeSpectrum> v;
    for (int i = 0; i < detail::kNumFiberDyes; ++i)
      v.push_back(parse_dye_spectrum(detail::kFiberDyes[i].json,
                                     std::string("dye:") + detail::kFiberDyes[i].name));
    return v;
  }();
  for (const auto& d : dyes)
    if (d.name == name) return d;
  std::string list;
  for (const auto& d : dyes) list += (list.empty() ? "" : ", ") + d.name;
  throw Error(file, field, "unknown dye '" + name + "' (bundled dyes: " + list + ")");
}

double dye_mol_per_L(const DyeComponent& component, double fiber_density_g_cm3) {
  const double molar_mass = bundled_dye(component.dye, "", "dye").molar_mass_g_per_mol;
  const double grams_per_L = component.concentration_owf_percent / 100 * component.uptake_fraction *
                             fiber_density_g_cm3 * 1000;
  return grams_per_L / molar_mass;
}

Spectrum dye_absorption_per_um(const Spectrum& epsilon_per_M_per_cm, double mol_per_L) {
  Spectrum a{};
  for (int b = 0; b < kNumBands; ++b)
    a[b] = std::numbers::ln10 * epsilon_per_M_per_cm[b] * mol_per_L * 1e-4;
  return a;
}

Spectrum recipe_absorption_per_um(const std::vector<DyeComponent>& recipe,
                                  double fiber_density_g_cm3) {
  Spectrum total{};
  for (const auto& c : recipe) {
    const Spectrum a = dye_absorption_per_um(bundled_dye(c.dye, "", "dye").epsilon_per_M_per_cm,
                                             dye_mol_per_L(c, fiber_density_g_cm3));
    for (int b = 0; b < kNumBands; ++b) total[b] += a[b];
  }
  return total;
}

}  // namespace weft
