// Tests of the fiber medium built from a fiber spec (the spec itself is tested in
// test_fiber_spec.cpp). Reference values are derived independently: from the Mie solver (itself
// validated in test_mie.cpp against Wiscombe's and Du's tables) through the closed-form number
// densities N = f_v / (4/3 pi r^3) and, for a lognormal, <r^3> = r_med^3 exp(9 sigma^2 / 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/mie.h"

using namespace weft;

namespace {

using weft::testing::relative_difference;

// A fiber of radius 5 um, host n = 1.5 absorbing 0.01 / um, with one species of particles of index
// 2 + i k and the given sizes at volume fraction 0.01; built as a value, since parsing is not
// what these tests check.
FiberSpec one_species_spec(const SizeDistribution& size, double particle_k) {
  FiberSpec s;
  s.name = "test";
  s.fiber_radius_um = 5;
  s.roughness_distribution = MicrofacetModel::kGgx;
  s.roughness_alpha = 0.2;
  s.host_n.fill(1.5);
  s.host_absorption_per_um.fill(0.01);
  ParticleSpecies p;
  p.name = "s";
  p.n.fill(2.0);
  p.k.fill(particle_k);
  p.size = size;
  p.volume_fraction = 0.01;
  s.species = {p};
  return s;
}

}  // namespace

TEST(FiberMedium, MonodisperseSpeciesMatchesClosedForm) {
  const FiberSpec s = one_species_spec(SizeDistribution::monodisperse(0.2), 0.0);
  for (int band : {0, 16, 32}) {
    const MediumBand m = compute_medium_band(s, band);
    const double wl = band_wavelength_nm(band);
    const MieResult r = mie_sphere_physical(2.0, 0.0, 1.5, 0.2, wl);
    const double n = 0.01 / (4.0 / 3.0 * std::numbers::pi * 0.008);
    EXPECT_LE(relative_difference(m.mu_s_per_um, n * std::numbers::pi * 0.04 * r.qsca), 1e-12);
    EXPECT_EQ(m.mu_a_particles_per_um, 0.0);
    EXPECT_NEAR(m.mu_a_host_per_um, 0.99 * 0.01, 1e-15);
    EXPECT_NEAR(m.albedo, m.mu_s_per_um / (m.mu_s_per_um + m.mu_a_per_um), 1e-15);
    EXPECT_NEAR(m.g, r.g, 1e-12);
    EXPECT_EQ(m.wavelength_nm, wl);
    EXPECT_EQ(m.host_n, 1.5);
  }
}

TEST(FiberMedium, LognormalAndAbsorbingSpecies) {
  // Lognormal number density from the mean volume 4/3 pi r_med^3 exp(9 sigma^2 / 2), absorbing
  // particles adding N <C_abs>.
  const FiberSpec s = one_species_spec(SizeDistribution::lognormal(0.15, 0.3), 0.05);
  const MediumBand m = compute_medium_band(s, 10);
  const double mu[] = {1.0};
  const MieEnsemble e = mie_ensemble(2.0, 0.05, 1.5, SizeDistribution::lognormal(0.15, 0.3),
                                     band_wavelength_nm(10), mu, {64});
  const double mean_volume =
      4.0 / 3.0 * std::numbers::pi * std::pow(0.15, 3) * std::exp(4.5 * 0.09);
  EXPECT_LE(relative_difference(e.mean_volume_um3, mean_volume), 1e-6);
  const double n = 0.01 / mean_volume;
  EXPECT_LE(relative_difference(m.mu_s_per_um, n * e.mean_csca_um2), 1e-5);
  EXPECT_LE(relative_difference(m.mu_a_particles_per_um, n * e.mean_cabs_um2), 1e-5);
  EXPECT_GT(m.mu_a_particles_per_um, 0.0);
}

TEST(FiberMedium, EmptyMediumIsIsotropicAndHostOnly) {
  const FiberSpec s = parse_fiber_spec(
      R"({"name": "e", "fiber_radius_um": 5, "roughness": {"distribution": "ggx", "alpha": 0.2},
          "host": {"n": 1.5, "absorption_per_um": 0.02}, "species": []})",
      "spec.json");
  const MediumBand m = compute_medium_band(s, 5);
  EXPECT_EQ(m.mu_s_per_um, 0.0);
  EXPECT_EQ(m.mu_a_per_um, 0.02);
  EXPECT_EQ(m.albedo, 0.0);
  EXPECT_NEAR(m.phase.mean_cosine(), 0.0, 1e-15);
  EXPECT_NEAR(m.phase.eval(0.3), 1 / (4 * std::numbers::pi), 1e-15);
}

TEST(FiberMedium, PresetPhaseTablesReproduceMieAsymmetry) {
  // For every preset and band: the tabulated phase function's exact mean cosine and the mean of
  // 20000 stratified samples drawn through its inverse CDF match Mie's g to 1e-3; the medium
  // is physical (0 <= albedo <= 1, mu_s > 0).
  for (const auto& name : fiber_preset_names()) {
    const FiberMedium med = build_fiber_medium(load_fiber_spec(name));
    ASSERT_EQ(med.bands.size(), static_cast<size_t>(kNumBands));
    EXPECT_EQ(med.spec_hash, fiber_spec_hash_hex(load_fiber_spec(name)));
    for (const auto& b : med.bands) {
      EXPECT_GT(b.mu_s_per_um, 0.0) << name << " " << b.wavelength_nm;
      EXPECT_GE(b.albedo, 0.0);
      EXPECT_LE(b.albedo, 1.0);
      EXPECT_NEAR(b.phase.mean_cosine(), b.g, 1e-3) << name << " " << b.wavelength_nm;
      const int n = 20000;
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += b.phase.sample_cos_theta((i + 0.5) / n);
      EXPECT_NEAR(sum / n, b.g, 1e-3) << name << " " << b.wavelength_nm;
    }
  }
  // The dye makes red cotton absorb in the green far more than in the red; white cotton is
  // lossless. Its recipe (docs/presets.md: Congo red, a broad band whose tail reaches 670 nm)
  // gives albedos of 0.15 at 530 nm and 0.79 at 670 nm.
  const FiberMedium red = build_fiber_medium(load_fiber_spec("red-cotton"));
  const FiberMedium white = build_fiber_medium(load_fiber_spec("white-cotton"));
  EXPECT_LT(red.bands[14].albedo, 0.5);   // 530 nm
  EXPECT_GT(red.bands[28].albedo, 0.75);  // 670 nm
  EXPECT_GT(red.bands[28].mu_s_per_um / red.bands[28].mu_a_per_um,
            10 * red.bands[14].mu_s_per_um / red.bands[14].mu_a_per_um);
  for (const auto& b : white.bands) EXPECT_EQ(b.mu_a_per_um, 0.0);
}

TEST(FiberMedium, SameBitsAtAnyThreadCount) {
  const FiberSpec s = load_fiber_spec("red-cotton");
  const int bands[] = {0, 7, 16, 31};
  MediumOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const FiberMedium a = build_fiber_medium(s, bands, one);
  const FiberMedium b = build_fiber_medium(s, bands, two);
  ASSERT_EQ(a.bands.size(), 4u);
  for (size_t i = 0; i < a.bands.size(); ++i) {
    EXPECT_EQ(a.bands[i].band, bands[i]);
    EXPECT_EQ(a.bands[i].mu_s_per_um, b.bands[i].mu_s_per_um);
    EXPECT_EQ(a.bands[i].mu_a_per_um, b.bands[i].mu_a_per_um);
    EXPECT_EQ(a.bands[i].g, b.bands[i].g);
    for (double mu : {-1.0, 0.0, 0.9, 0.999, 1.0})
      EXPECT_EQ(a.bands[i].phase.eval(mu), b.bands[i].phase.eval(mu));
  }
  const int bad[] = {33};
  EXPECT_THROW(build_fiber_medium(s, bad), Error);
  // Cancellation through the progress callback.
  EXPECT_THROW(build_fiber_medium(s, {}, one, [](const ProgressUpdate&) { return false; }), Error);
}

TEST(Medium, PresetsDocMatchesTheMedium) {
  // docs/presets.md tabulates what each preset produces at single wavelengths: the numbers users
  // read must be the ones the code computes (to the digits printed).
  std::ifstream doc(std::string(WEFT_SOURCE_DIR) + "/docs/presets.md");
  ASSERT_TRUE(doc) << "docs/presets.md";
  std::string line;
  int rows = 0;
  while (std::getline(doc, line)) {
    // | preset | nm | mu_s | mu_a | albedo | g |, single-wavelength rows only.
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, '|')) {
      const auto b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
      cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
    }
    if (cells.size() < 7) continue;
    const std::string preset = cells[1];
    const auto presets = fiber_preset_names();
    if (std::find(presets.begin(), presets.end(), preset) == presets.end()) continue;
    if (cells[2].find_first_not_of("0123456789") != std::string::npos) continue;  // a range
    const double nm = std::stod(cells[2]);
    const MediumBand mb = compute_medium_band(load_fiber_spec(preset),
                                              static_cast<int>(std::lround((nm - 390) / 10)));
    const double values[4] = {mb.mu_s_per_um, mb.mu_a_per_um, mb.albedo, mb.g};
    for (int k = 0; k < 4; ++k) {
      const std::string& text = cells[3 + k];
      const auto dot = text.find('.');
      const double last_digit =
          dot == std::string::npos ? 1 : std::pow(10.0, -static_cast<int>(text.size() - dot - 1));
      EXPECT_NEAR(std::stod(text), values[k], 0.51 * last_digit)
          << preset << " " << nm << " col " << k;
    }
    ++rows;
  }
  // Three wavelengths per preset; white-cotton has one row for the range instead.
  EXPECT_GE(rows, 3 * static_cast<int>(fiber_preset_names().size()) - 3);
}
