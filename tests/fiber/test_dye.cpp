// Tests of dyes and dye recipes (fiber/dye.h) and of the spec's host.dyes: the Beer-Lambert
// absorption of a recipe against a hand computation, linearity in the concentrations, the bundled
// dyes and their tabulated spectra, refusal of bad recipes and bad spectra naming the field, and
// the hash covering the recipe.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fiber/dye.h"
#include "weft/fiber/fiber_spec.h"

using namespace weft;
using weft::testing::error_of;

namespace {

// A spec with a recipe; 'dyes' is the JSON array of host.dyes.
std::string dyed_spec(const std::string& dyes, const std::string& extra_host = "") {
  return R"({"name": "dyed", "fiber_radius_um": 5, "density_g_cm3": 1.52,
    "roughness": {"distribution": "ggx", "alpha": 0.2},
    "host": {"n": 1.5, )" +
         extra_host + R"("dyes": )" + dyes + R"(},
    "species": []})";
}

// 'text' with its first 'from' replaced by 'to'.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

int band_of_nm(double nm) {
  return static_cast<int>(std::lround((nm - kFirstBandNm) / kBandStepNm));
}

}  // namespace

// Congo red (C.I. Direct Red 28), 1 % owf, all taken up, in cellulose of 1.52 g/cm^3, in the band
// of its peak (483 nm in the PhotochemCAD spectrum, record J17; fiber/data/dyes/README.md): the
// band 475-485 nm averages epsilon = 47641.6 L/(mol cm) (the trapezoid rule over the file's 1 nm
// rows, computed apart from the program). By hand:
//   c = 0.01 * 1.52 g/cm^3 * 1000 cm^3/L / 696.66 g/mol = 0.0218184 mol/L
//   mu_a = ln(10) * 47641.6 * 0.0218184 * 1e-4 = 0.239345 per um.
TEST(Dye, OneDyeRecipeIsBeerLambertAtLambdaMax) {
  const DyeSpectrum& congo = bundled_dye("congo-red", "", "");
  EXPECT_EQ(congo.molar_mass_g_per_mol, 696.66);
  const int b480 = band_of_nm(480);
  EXPECT_NEAR(congo.epsilon_per_M_per_cm[b480], 47641.6, 0.05);
  const FiberSpec s = parse_fiber_spec(
      dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1}])"), "spec.json");
  ASSERT_EQ(s.dyes.size(), 1u);
  EXPECT_EQ(s.dyes[0].uptake_fraction, 1);  // the default
  EXPECT_NEAR(dye_mol_per_L(s.dyes[0], 1.52), 0.0218184, 1e-7);
  EXPECT_NEAR(host_total_absorption_per_um(s)[b480], 0.239345, 1e-6);
  // The band falls off on both sides.
  const Spectrum a = host_total_absorption_per_um(s);
  EXPECT_LT(a[band_of_nm(450)], a[b480]);
  EXPECT_LT(a[band_of_nm(550)], a[b480]);
  EXPECT_LT(a[band_of_nm(700)], 0.05 * a[b480]);
}

// Absorption is linear in each concentration and adds over dyes and to the absorption given.
TEST(Dye, ConcentrationsAddLinearly) {
  auto total = [](const std::string& dyes, const std::string& extra = "") {
    return host_total_absorption_per_um(parse_fiber_spec(dyed_spec(dyes, extra), "spec.json"));
  };
  const Spectrum red1 = total(R"([{"dye": "congo-red", "concentration_owf_percent": 1}])");
  const Spectrum red3 = total(R"([{"dye": "congo-red", "concentration_owf_percent": 3}])");
  const Spectrum red_half =
      total(R"([{"dye": "congo-red", "concentration_owf_percent": 1, "uptake_fraction": 0.5}])");
  const Spectrum yellow = total(R"([{"dye": "curcumin", "concentration_owf_percent": 0.5}])");
  const Spectrum both = total(R"([{"dye": "congo-red", "concentration_owf_percent": 1},
                                  {"dye": "curcumin", "concentration_owf_percent": 0.5}])");
  const Spectrum plus = total(R"([{"dye": "congo-red", "concentration_owf_percent": 1}])",
                              R"("absorption_per_um": 0.002, )");
  for (int b = 0; b < kNumBands; ++b) {
    EXPECT_NEAR(red3[b], 3 * red1[b], 1e-14) << b;
    EXPECT_NEAR(red_half[b], 0.5 * red1[b], 1e-14) << b;
    EXPECT_NEAR(both[b], red1[b] + yellow[b], 1e-14) << b;
    EXPECT_NEAR(plus[b], red1[b] + 0.002, 1e-14) << b;
  }
  // Curcumin is the yellow: it absorbs more than Congo red at 420 nm, less at 500 nm.
  EXPECT_GT(yellow[band_of_nm(420)], red1[band_of_nm(420)]);
  EXPECT_LT(yellow[band_of_nm(500)], red1[band_of_nm(500)]);
}

// Every bundled dye parses, has its absorption from a tabulated spectrum and a molar mass; at
// least a red, a yellow and a blue are bundled so that common shades can be mixed.
TEST(Dye, BundledDyes) {
  const auto names = bundled_dye_names();
  EXPECT_GE(names.size(), 3u);
  for (const char* n : {"congo-red", "curcumin", "evans-blue"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  for (const auto& n : names) {
    const DyeSpectrum& d = bundled_dye(n, "", "");
    EXPECT_EQ(d.name, n);
    EXPECT_TRUE(d.tabulated) << n;
    EXPECT_GT(d.molar_mass_g_per_mol, 100) << n;
    for (double e : d.epsilon_per_M_per_cm) EXPECT_GE(e, 0) << n;
  }
  // Peak bands of the spectra (fiber/data/dyes/README.md): Congo red 483 nm, curcumin 425 nm
  // (the edge of the 430 nm band, whose side toward the peak is the higher), Evans blue 606 nm.
  auto peak_nm = [](const std::string& n) {
    const Spectrum& e = bundled_dye(n, "", "").epsilon_per_M_per_cm;
    return band_wavelength_nm(static_cast<int>(std::max_element(e.begin(), e.end()) - e.begin()));
  };
  EXPECT_EQ(peak_nm("congo-red"), 480);
  EXPECT_EQ(peak_nm("curcumin"), 430);
  EXPECT_EQ(peak_nm("evans-blue"), 610);
}

// Each bundled spectrum is scaled as its PhotochemCAD record states: epsilon_max at the measured
// lambda_max (records J17, D08, J19, L01, N11, L03, I12 of the database's table of records,
// github.com/yaxue1123/photochemcad sql/records.sql at commit 5e2ed5f). The band holding
// lambda_max averages the peak over 10 nm, so it lies at or below epsilon_max, by the band's
// curvature: 12 % allows the narrowest, methylene blue's (656 nm, about 9 % below).
TEST(Dye, BundledSpectraMeetTheirRecordsAtLambdaMax) {
  struct Record {
    const char* dye;
    double lambda_max_nm, epsilon_max;
  };
  const Record records[] = {{"congo-red", 483, 48000},       {"curcumin", 425, 55000},
                            {"evans-blue", 606, 86000},      {"auramine-o", 431.25, 25300},
                            {"rhodamine-b", 542.75, 106000}, {"crystal-violet", 590.5, 75800},
                            {"methylene-blue", 656, 40700}};
  EXPECT_EQ(bundled_dye_names().size(), std::size(records));
  for (const Record& r : records) {
    const double e = bundled_dye(r.dye, "", "").epsilon_per_M_per_cm[band_of_nm(r.lambda_max_nm)];
    EXPECT_LE(e, r.epsilon_max * (1 + 1e-12)) << r.dye;
    EXPECT_GE(e, 0.88 * r.epsilon_max) << r.dye;
  }
}

// Congo red hardly absorbs red light: its PhotochemCAD spectrum (record J17, in PBS) reads
// epsilon = 272 at 630 nm and 145 at 650 nm, 0.6 % and 0.3 % of its 48 000 peak. The Gaussian band
// estimated before (FWHM 4700 cm^-1) kept 7 % at 650 nm and turned a red cloth brown.
TEST(Dye, CongoRedHardlyAbsorbsInTheRed) {
  const Spectrum& e = bundled_dye("congo-red", "", "").epsilon_per_M_per_cm;
  const double peak = e[band_of_nm(480)];
  EXPECT_LT(e[band_of_nm(630)], 0.01 * peak);
  EXPECT_LT(e[band_of_nm(650)], 0.01 * peak);
  EXPECT_GT(e[band_of_nm(650)], 0);  // measured, not cut off
}

namespace {

// A dye file with the given absorption keys (a spectrum, bands or both).
std::string dye_file(const std::string& absorption) {
  return R"({"name": "test-dye", "colour_index": "-", "use": "-", "formula": "-",
    "molar_mass_g_per_mol": 500, "solvent": "water", "source": "-", )" +
         absorption + "}";
}

}  // namespace

// A tabulated spectrum is averaged over each band, 0 past its ends; the band format still works.
TEST(Dye, SpectrumAndBandFormats) {
  // A triangle rising from 0 at 480 nm to 1000 at 500 nm and back to 0 at 520 nm: the 500 nm band
  // (495-505 nm) averages 1000 * (1 - 2.5 / 20) = 875, the 490 nm band (485-495) 500, the 480 nm
  // band (475-485) 1000 * 2.5 * 0.25 / 10 = 62.5 (the table starts at 480 nm).
  const DyeSpectrum t = parse_dye_spectrum(
      dye_file(R"("spectrum_nm_epsilon_per_M_per_cm": [[480, 0], [500, 1000], [520, 0]])"),
      "t.json");
  EXPECT_TRUE(t.tabulated);
  EXPECT_NEAR(t.epsilon_per_M_per_cm[band_of_nm(500)], 875, 1e-9);
  EXPECT_NEAR(t.epsilon_per_M_per_cm[band_of_nm(490)], 500, 1e-9);
  EXPECT_NEAR(t.epsilon_per_M_per_cm[band_of_nm(480)], 62.5, 1e-9);
  EXPECT_EQ(t.epsilon_per_M_per_cm[band_of_nm(530)], 0);
  EXPECT_EQ(t.epsilon_per_M_per_cm[band_of_nm(400)], 0);
  // A Gaussian band peaks at its lambda_max (a band centre here) with its epsilon_max.
  const DyeSpectrum g = parse_dye_spectrum(
      dye_file(R"("bands": [{"lambda_max_nm": 500, "epsilon_max_per_M_per_cm": 48000,
                            "fwhm_per_cm": 4700}])"),
      "g.json");
  EXPECT_FALSE(g.tabulated);
  EXPECT_DOUBLE_EQ(g.epsilon_per_M_per_cm[band_of_nm(500)], 48000);
  EXPECT_LT(g.epsilon_per_M_per_cm[band_of_nm(450)], 48000);
}

// A malformed spectrum is refused naming the file and the field.
TEST(Dye, MalformedSpectrumIsRefusedNamingTheField) {
  auto expect_error = [](const std::string& absorption,
                         std::initializer_list<std::string> fragments) {
    const std::string what =
        error_of([&] { parse_dye_spectrum(dye_file(absorption), "my-dye.json"); });
    ASSERT_FALSE(what.empty()) << "no error for " << absorption;
    EXPECT_NE(what.find("my-dye.json"), std::string::npos) << what;
    for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what;
  };
  const std::string key = R"("spectrum_nm_epsilon_per_M_per_cm": )";
  expect_error(key + "[[300, 0], [500, 10], [490, 0], [800, 0]]",
               {"spectrum_nm_epsilon_per_M_per_cm[2][0]", "increase"});
  expect_error(key + "[[300, 0], [500, -10], [800, 0]]",
               {"spectrum_nm_epsilon_per_M_per_cm[1][1]"});
  expect_error(key + R"([[300, 0], [500, "10"], [800, 0]])",
               {"spectrum_nm_epsilon_per_M_per_cm[1][1]"});
  expect_error(key + "[[300, 0], [500, 1e7], [800, 0]]",
               {"spectrum_nm_epsilon_per_M_per_cm[1][1]"});
  expect_error(key + "[[300, 0], [500], [800, 0]]",
               {"spectrum_nm_epsilon_per_M_per_cm[1]", "pair"});
  expect_error(key + "[[300, 0], [5000, 10]]", {"spectrum_nm_epsilon_per_M_per_cm[1][0]"});
  expect_error(key + "[[500, 10]]", {"spectrum_nm_epsilon_per_M_per_cm", "2 to"});
  expect_error(key + "{}", {"spectrum_nm_epsilon_per_M_per_cm", "array"});
  expect_error(key + "[[300, 0], [800, 0]]", {"spectrum_nm_epsilon_per_M_per_cm", "no absorption"});
  // Stopping at 600 nm at half the peak would drop absorption that is there.
  expect_error(key + "[[300, 0], [500, 1000], [600, 500]]",
               {"spectrum_nm_epsilon_per_M_per_cm", "600 nm", "died away"});
  // Too many rows.
  std::string rows = "[";
  for (size_t i = 0; i <= kMaxDyeSpectrumRows; ++i)
    rows += (i ? ", [" : "[") + std::to_string(300 + 0.01 * static_cast<double>(i)) + ", 1]";
  expect_error(key + rows + "]", {"spectrum_nm_epsilon_per_M_per_cm", "10000"});
  // Both forms, or neither.
  expect_error(key + R"([[300, 0], [500, 10], [800, 0]], "bands": [])", {"bands", "not both"});
  expect_error(R"("peak_nm": 500)", {"spectrum_nm_epsilon_per_M_per_cm", "neither"});
}

TEST(Dye, BadRecipesAreRefusedNamingTheField) {
  auto expect_error = [](const std::string& json, std::initializer_list<std::string> fragments) {
    const std::string what = error_of([&] { parse_fiber_spec(json, "spec.json"); });
    ASSERT_FALSE(what.empty()) << "no error for " << json;
    EXPECT_NE(what.find("spec.json"), std::string::npos) << what;
    for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what;
  };
  expect_error(dyed_spec(R"([{"dye": "mauveine", "concentration_owf_percent": 1}])"),
               {"host.dyes[0].dye", "unknown dye 'mauveine'", "congo-red", "curcumin"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": -1}])"),
               {"host.dyes[0].concentration_owf_percent"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1},
                             {"dye": "curcumin", "concentration_owf_percent": 250}])"),
               {"host.dyes[1].concentration_owf_percent"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": "2"}])"),
               {"host.dyes[0].concentration_owf_percent"});
  expect_error(dyed_spec(R"([{"dye": "congo-red"}])"), {"host.dyes[0].concentration_owf_percent"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1,
                             "uptake_fraction": 0}])"),
               {"host.dyes[0].uptake_fraction"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1, "owf": 2}])"),
               {"host.dyes[0]", "owf"});
  expect_error(dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1},
                             {"dye": "congo-red", "concentration_owf_percent": 2}])"),
               {"host.dyes[1].dye", "twice"});
  expect_error(dyed_spec("[]"), {"host.dyes", "non-empty"});
  // The fibre's density is needed with dyes, and in range; the old place inside host is refused.
  const std::string one = dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1}])");
  expect_error(replaced(one, "\"density_g_cm3\": 1.52,", ""), {"density_g_cm3", "required"});
  expect_error(replaced(one, "1.52", "152"), {"density_g_cm3"});
  expect_error(replaced(one, "\"n\": 1.5, ", "\"n\": 1.5, \"density_g_per_cm3\": 1.52, "),
               {"host", "density_g_per_cm3"});
}

// The hash covers the recipe: a concentration, an uptake or a dye changes it; a spec without a
// recipe keeps the canonical form it had before recipes existed (no "dyes" key).
TEST(Dye, HashCoversTheRecipe) {
  auto hash = [](const std::string& dyes) {
    return fiber_spec_hash_hex(parse_fiber_spec(dyed_spec(dyes), "spec.json"));
  };
  const std::string h = hash(R"([{"dye": "congo-red", "concentration_owf_percent": 2}])");
  EXPECT_EQ(h, hash(R"([{"concentration_owf_percent": 2.0, "dye": "congo-red"}])"));
  EXPECT_NE(h, hash(R"([{"dye": "congo-red", "concentration_owf_percent": 2.1}])"));
  EXPECT_NE(h, hash(R"([{"dye": "congo-red", "concentration_owf_percent": 2,
                         "uptake_fraction": 0.9}])"));
  EXPECT_NE(h, hash(R"([{"dye": "evans-blue", "concentration_owf_percent": 2}])"));
  const FiberSpec plain = parse_fiber_spec(R"({"name": "x", "fiber_radius_um": 5,
    "roughness": {"distribution": "ggx", "alpha": 0.2}, "host": {"n": 1.5}, "species": []})",
                                           "spec.json");
  EXPECT_EQ(canonical_json(plain).find("dyes"), std::string::npos);
}

// The bundled red-cotton preset is dyed by its recipe (docs/presets.md): Congo red with a little
// curcumin, and its absorption is the recipe's.
TEST(Dye, RedCottonIsDyedByItsRecipe) {
  const FiberSpec s = load_fiber_spec("red-cotton");
  ASSERT_EQ(s.dyes.size(), 2u);
  EXPECT_EQ(s.dyes[0].dye, "congo-red");
  EXPECT_EQ(s.dyes[1].dye, "curcumin");
  const Spectrum a = host_total_absorption_per_um(s);
  const Spectrum r = recipe_absorption_per_um(s.dyes, s.density_g_cm3);
  for (int b = 0; b < kNumBands; ++b) EXPECT_EQ(a[b], r[b]);
  // A red: it absorbs blue and green far more than red light.
  EXPECT_GT(a[band_of_nm(500)], 10 * a[band_of_nm(700)]);
  EXPECT_GT(a[band_of_nm(420)], a[band_of_nm(650)]);
}
