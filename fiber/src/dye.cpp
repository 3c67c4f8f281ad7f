#include "weft/fiber/dye.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "embedded_json.h"
#include "weft/core/error.h"
#include "weft/core/params.h"

namespace weft {

DyeSpectrum parse_dye_spectrum(const std::string& json_text, const std::string& file) {
  const nlohmann::json root = parse_json(json_text, file);
  ParamReader p(root, file, "");
  DyeSpectrum d;
  d.name = p.string("name");
  d.colour_index = p.string("colour_index");
  for (const char* key : {"use", "formula", "solvent", "source"}) (void)p.string(key);
  d.molar_mass_g_per_mol = p.number("molar_mass_g_per_mol", 1, 1e5);
  const nlohmann::json& bands = p.at("bands");
  if (!bands.is_array() || bands.empty())
    throw Error(file, "bands", "must be a non-empty array of absorption bands");
  for (size_t i = 0; i < bands.size(); ++i) {
    ParamReader b(bands[i], file, "bands[" + std::to_string(i) + "]");
    // Ultraviolet to near-infrared bands; an electronic band is a few hundred to some thousands
    // of wavenumbers wide.
    const double lambda_max_nm = b.number("lambda_max_nm", 200, 1200);
    const double epsilon_max = b.number("epsilon_max_per_M_per_cm", 1e-300, 1e6);
    const double fwhm_per_cm = b.number("fwhm_per_cm", 100, 20000);
    b.finish();
    const double nu_max = 1e7 / lambda_max_nm;
    for (int k = 0; k < kNumBands; ++k) {
      const double nu = 1e7 / band_wavelength_nm(k);
      d.epsilon_per_M_per_cm[k] +=
          epsilon_max * std::exp(-4 * std::numbers::ln2 * (nu - nu_max) * (nu - nu_max) /
                                 (fwhm_per_cm * fwhm_per_cm));
    }
  }
  p.finish();
  return d;
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
