#pragma once
// Textile dyes and dye recipes: the bundled dyes' molar absorption spectra (fiber/data/dyes/*.json,
// compiled in like the presets; sources in fiber/data/dyes/README.md) and the Beer-Lambert
// absorption of a recipe dissolved in a fibre.
//
// A recipe states each dye as dyers do, in percent on the weight of fibre (owf): grams of dye
// applied per 100 g of fibre, of which the uptake fraction ends up in the fibre. With the fibre's
// density rho (g/cm^3) and the dye's molar mass M (g/mol) the dye's concentration in the fibre is
//   c = owf/100 * uptake * rho * 1000 / M   mol/L,
// and its absorption coefficient, summed over the recipe,
//   mu_a(lambda) = ln(10) * epsilon(lambda) * c * 1e-4   per um
// (epsilon in L mol^-1 cm^-1 is decadic and per cm; 1e-4 turns per cm into per um).
//
// Dye file layout (every key required but "dye_class", and the absorption as one of two keys):
// {"name": "congo-red", "colour_index": "...", "use": "...", "formula": "...",
//  "molar_mass_g_per_mol": 696.66, "solvent": "...", "source": "...", "dye_class": "direct",
//  "spectrum_nm_epsilon_per_M_per_cm": [[380, 25371], [381, 25043], ...]}
// A tabulated spectrum (a measured one, as the bundled dyes carry): rows of wavelength (nm,
// increasing) and epsilon, joined linearly and averaged over each band; epsilon is 0 past the
// table's ends, so a table stopping inside the bands must stop where its absorption has died away
// (below kDyeSpectrumEndFraction of its peak). Or, where no spectrum is at hand, Gaussian bands:
//  "bands": [{"lambda_max_nm": 500, "epsilon_max_per_M_per_cm": 48000, "fwhm_per_cm": 4700}]
// each a Gaussian in wavenumber (the usual shape of a broad electronic absorption band), summed:
//   epsilon(nu) = epsilon_max * exp(-4 ln 2 (nu - nu_max)^2 / fwhm^2),  nu = 1e7 / lambda_nm per
//   cm.
#include <cstddef>
#include <string>
#include <vector>

#include "weft/core/spectrum.h"

namespace weft {

struct DyeSpectrum {
  std::string name;          // e.g. "congo-red"
  std::string colour_index;  // e.g. "C.I. Direct Red 28 ..."
  double molar_mass_g_per_mol = 0;
  Spectrum epsilon_per_M_per_cm{};  // decadic molar absorption coefficient per band
  bool tabulated = false;           // from a tabulated spectrum (else from Gaussian bands)
  // The application class dyers sort dyes by ("direct" for cotton, "basic" for acrylic): dyes of
  // one class go on one fibre in one bath. Optional key "dye_class"; "" where not given.
  std::string dye_class;
};

// A dye's place in a trichromatic set, by the band it absorbs most (its peak): yellow below
// 470 nm (absorbs blue), red 470-570 nm (absorbs green), blue above 570 nm (absorbs orange and
// red). Three dyes of one class, one of each, reach the colours between them; dyehouses match a
// shade with such a set.
enum class DyeHue { kYellow, kRed, kBlue };
DyeHue dye_hue(const DyeSpectrum& dye);
// The centre of the band where the dye absorbs most, nm.
double dye_peak_nm(const DyeSpectrum& dye);

// The tabulated spectrum's key and bounds. Spectrophotometers read 190-1100 nm; a 0.1 nm table of
// that range has about 9000 rows, and 10 000 refuses absurd ones. The strongest dyes reach
// epsilon of some 300 000 L/(mol cm) (cyanines); 1e6 refuses unit slips.
inline constexpr const char* kDyeSpectrumKey = "spectrum_nm_epsilon_per_M_per_cm";
inline constexpr size_t kMaxDyeSpectrumRows = 10000;
inline constexpr double kMinDyeSpectrumNm = 190, kMaxDyeSpectrumNm = 1100;
inline constexpr double kMaxDyeEpsilon = 1e6;
// A table that stops inside the bands ends below this fraction of its peak (the bundled ones end
// at 0.4 % at most: auramine O's at 600 nm).
inline constexpr double kDyeSpectrumEndFraction = 0.01;
// Gaussian bands in one file: a dye's visible and near-UV bands are a handful.
inline constexpr size_t kMaxDyeGaussianBands = 16;

// One dye of a recipe (the spec's host.dyes[i]).
struct DyeComponent {
  std::string dye;                       // a bundled dye's name
  double concentration_owf_percent = 0;  // applied, on the weight of fibre
  double uptake_fraction = 1;            // share of the applied dye that ends up in the fibre
};

// Bounds checked when a recipe is read. Deep shades (blacks, navies) use up to about 8-10 % owf;
// 20 % leaves room and refuses unit slips (a fraction written as grams per kg).
inline constexpr double kMaxDyeOwfPercent = 20;
// Presets carry one to three dyes; real recipes rarely exceed four.
inline constexpr int kMaxDyeComponents = 8;

// Parses a dye file's JSON; 'file' names it in errors.
DyeSpectrum parse_dye_spectrum(const std::string& json_text, const std::string& file);
// The bundled dyes' names, sorted as compiled in.
std::vector<std::string> bundled_dye_names();
// A bundled dye; weft::Error naming 'file' and 'field' and listing the bundled dyes otherwise.
const DyeSpectrum& bundled_dye(const std::string& name, const std::string& file,
                               const std::string& field);

// The dye's concentration in the fibre, mol/L (formula above).
double dye_mol_per_L(const DyeComponent& component, double fiber_density_g_cm3);
// ln(10) * epsilon * c * 1e-4 per band, per um.
Spectrum dye_absorption_per_um(const Spectrum& epsilon_per_M_per_cm, double mol_per_L);
// The recipe's absorption, summed over its bundled dyes, per um.
Spectrum recipe_absorption_per_um(const std::vector<DyeComponent>& recipe,
                                  double fiber_density_g_cm3);

}  // namespace weft
