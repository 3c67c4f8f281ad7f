// Tests of dyes and dye recipes (fiber/dye.h) and of the spec's host.dyes: the Beer-Lambert
// absorption of a recipe against a hand computation, linearity in the concentrations, the bundled
// dyes, refusal of bad recipes naming the field, and the hash covering the recipe.
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

// Congo red (C.I. Direct Red 28), 1 % owf, all taken up, in cellulose of 1.52 g/cm^3, at its
// lambda_max of 500 nm, where epsilon = 48000 L/(mol cm) (Tanizaki 1957 as quoted by the
// PhotochemCAD database, record J17; fiber/data/dyes/README.md). By hand:
//   c = 0.01 * 1.52 g/cm^3 * 1000 cm^3/L / 696.66 g/mol = 0.0218184 mol/L
//   mu_a = ln(10) * 48000 * 0.0218184 * 1e-4 = 0.241146 per um.
TEST(Dye, OneDyeRecipeIsBeerLambertAtLambdaMax) {
  const DyeSpectrum& congo = bundled_dye("congo-red", "", "");
  EXPECT_EQ(congo.molar_mass_g_per_mol, 696.66);
  const int b500 = band_of_nm(500);
  EXPECT_DOUBLE_EQ(congo.epsilon_per_M_per_cm[b500], 48000);
  const FiberSpec s = parse_fiber_spec(
      dyed_spec(R"([{"dye": "congo-red", "concentration_owf_percent": 1}])"), "spec.json");
  ASSERT_EQ(s.dyes.size(), 1u);
  EXPECT_EQ(s.dyes[0].uptake_fraction, 1);  // the default
  EXPECT_NEAR(dye_mol_per_L(s.dyes[0], 1.52), 0.0218184, 1e-7);
  EXPECT_NEAR(host_total_absorption_per_um(s)[b500], 0.241146, 1e-6);
  // The band falls off on both sides (a Gaussian in wavenumber, fiber/data/dyes/README.md).
  const Spectrum a = host_total_absorption_per_um(s);
  EXPECT_LT(a[band_of_nm(450)], a[b500]);
  EXPECT_LT(a[band_of_nm(550)], a[b500]);
  EXPECT_LT(a[band_of_nm(700)], 0.05 * a[b500]);
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

// Every bundled dye parses, has its peak where its file says and a molar mass; at least a red, a
// yellow and a blue are bundled so that common shades can be mixed.
TEST(Dye, BundledDyes) {
  const auto names = bundled_dye_names();
  EXPECT_GE(names.size(), 3u);
  for (const char* n : {"congo-red", "curcumin", "evans-blue"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  for (const auto& n : names) {
    const DyeSpectrum& d = bundled_dye(n, "", "");
    EXPECT_EQ(d.name, n);
    EXPECT_GT(d.molar_mass_g_per_mol, 100) << n;
    for (double e : d.epsilon_per_M_per_cm) EXPECT_GE(e, 0) << n;
  }
  // Peaks (fiber/data/dyes/*.json): Congo red 500 nm, curcumin 422 nm, Evans blue 606 nm.
  auto peak_nm = [](const std::string& n) {
    const Spectrum& e = bundled_dye(n, "", "").epsilon_per_M_per_cm;
    return band_wavelength_nm(static_cast<int>(std::max_element(e.begin(), e.end()) - e.begin()));
  };
  EXPECT_EQ(peak_nm("congo-red"), 500);
  EXPECT_EQ(peak_nm("curcumin"), 420);
  EXPECT_EQ(peak_nm("evans-blue"), 610);
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
