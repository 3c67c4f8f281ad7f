// Tests of the fiber spec: parsing, the three spectral forms, validation (errors name the file and
// the JSON path of the field), loading files and presets, and the canonical form and hash that
// name a spec in caches and table headers (name and notes excluded).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "test_util.h"
#include "weft/core/error.h"
#include "weft/fiber/fiber_spec.h"

using namespace weft;
using weft::testing::error_of;

namespace {

const char* kMinimal = R"({
  "name": "test",
  "fiber_radius_um": 5,
  "roughness": {"distribution": "ggx", "alpha": 0.2},
  "host": {"n": 1.5, "absorption_per_um": 0.01},
  "species": [{"name": "s", "n": 2.0, "k": 0.0, "volume_fraction": 0.01,
               "size": {"distribution": "monodisperse", "radius_um": 0.2}}]
})";

// Replaces the first occurrence of 'from' in kMinimal by 'to'.
std::string edit(const std::string& from, const std::string& to) {
  std::string s = kMinimal;
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

// Expects parse_fiber_spec to throw a weft::Error whose message names the file and holds every
// fragment.
void expect_error(const std::string& json, std::initializer_list<std::string> fragments) {
  const std::string what = error_of([&] { parse_fiber_spec(json, "spec.json"); });
  ASSERT_FALSE(what.empty()) << "no error for " << json;
  EXPECT_NE(what.find("spec.json"), std::string::npos) << what;
  for (const auto& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << what;
}

}  // namespace

TEST(FiberSpec, ParsesMinimalSpec) {
  const FiberSpec s = parse_fiber_spec(kMinimal, "spec.json");
  EXPECT_EQ(s.name, "test");
  EXPECT_EQ(s.fiber_radius_um, 5);
  EXPECT_EQ(s.roughness_distribution, MicrofacetModel::kGgx);
  EXPECT_EQ(s.roughness_alpha, 0.2);
  for (int b = 0; b < kNumBands; ++b) {
    EXPECT_EQ(s.host_n[b], 1.5);
    EXPECT_EQ(s.host_absorption_per_um[b], 0.01);
  }
  ASSERT_EQ(s.species.size(), 1u);
  EXPECT_EQ(s.species[0].size.kind, SizeDistribution::Kind::kMonodisperse);
  EXPECT_EQ(s.species[0].size.radius_um, 0.2);
  EXPECT_EQ(s.species[0].volume_fraction, 0.01);
}

TEST(FiberSpec, SpectralFormsAndUnits) {
  // Points are interpolated linearly: 390 -> 0, 710 -> 3.2 gives 0.01 per nm.
  FiberSpec s =
      parse_fiber_spec(edit("\"absorption_per_um\": 0.01",
                            "\"absorption_per_mm\": {\"points\": [[390, 0], [710, 3.2]]}"),
                       "spec.json");
  for (int b = 0; b < kNumBands; ++b)
    EXPECT_NEAR(s.host_absorption_per_um[b], 1e-3 * 0.01 * (band_wavelength_nm(b) - 390), 1e-15);
  // Points that reach beyond the range are fine; interior kinks are honoured.
  s = parse_fiber_spec(
      edit("\"n\": 2.0", "\"n\": {\"points\": [[380, 2.0], [550, 3.0], [720, 2.0]]}"), "spec.json");
  EXPECT_NEAR(s.species[0].n[16], 3.0, 1e-12);                       // 550 nm
  EXPECT_NEAR(s.species[0].n[0], 2.0 + (390 - 380) / 170.0, 1e-12);  // 390 nm
  // A 33-value array is taken band by band.
  std::string arr = "[";
  for (int b = 0; b < kNumBands; ++b)
    arr += std::to_string(1.4 + 0.001 * b) + (b + 1 < kNumBands ? "," : "]");
  s = parse_fiber_spec(edit("\"n\": 1.5", "\"n\": " + arr), "spec.json");
  EXPECT_NEAR(s.host_n[32], 1.432, 1e-12);
}

TEST(FiberSpec, RejectsBadInputNamingFileAndField) {
  expect_error(edit("\"name\": \"test\",", "\"name\": \"test\", \"colour\": 1,"),
               {"colour", "unknown key"});
  expect_error(edit("\"alpha\": 0.2", "\"alpha\": 0.2, \"beta\": 1"), {"roughness.beta"});
  expect_error(edit("\"radius_um\": 0.2", "\"radius_um\": 0.2, \"r\": 1"), {"species[0].size.r"});
  expect_error(edit("\"radius_um\": 0.2", "\"radius_um\": -0.2"), {"species[0].size.radius_um"});
  expect_error(edit("\"fiber_radius_um\": 5", "\"fiber_radius_um\": 0"), {"fiber_radius_um"});
  expect_error(edit("\"fiber_radius_um\": 5", "\"fiber_radius_um\": \"NaN\""),
               {"fiber_radius_um", "number"});
  expect_error(edit("\"fiber_radius_um\": 5", "\"fiber_radius_um\": 1e999"),
               {"fiber_radius_um", "out of range"});
  expect_error(edit("\"fiber_radius_um\": 5,", ""), {"fiber_radius_um", "is required"});
  expect_error(edit("\"volume_fraction\": 0.01", "\"volume_fraction\": 0.8"),
               {"species[0].volume_fraction", "0.74"});
  expect_error(edit("\"volume_fraction\": 0.01", "\"volume_fraction\": -0.01"),
               {"species[0].volume_fraction"});
  expect_error(edit("\"k\": 0.0", "\"k\": -0.1"), {"species[0].k"});
  expect_error(edit("\"n\": 1.5", "\"n\": 0"), {"host.n"});
  expect_error(edit("\"alpha\": 0.2", "\"alpha\": 0"), {"roughness.alpha"});
  expect_error(edit("\"ggx\"", "\"phong\""), {"roughness.distribution", "phong"});
  expect_error(edit("\"absorption_per_um\": 0.01", "\"absorption_per_um\": -1"),
               {"host.absorption_per_um"});
  expect_error(
      edit("\"absorption_per_um\": 0.01", "\"absorption_per_um\": 0.01, \"absorption_per_mm\": 1"),
      {"host"});
  expect_error(edit("\"absorption_per_um\": 0.01", "\"absorption_per_um\": [1, 2]"),
               {"host.absorption_per_um", "33"});
  expect_error(edit("\"absorption_per_um\": 0.01",
                    "\"absorption_per_um\": {\"points\": [[400, 1], [710, 1]]}"),
               {"host.absorption_per_um.points", "390"});
  expect_error(edit("\"absorption_per_um\": 0.01",
                    "\"absorption_per_um\": {\"points\": [[390, 1], [390, 1], [710, 1]]}"),
               {"host.absorption_per_um.points[1]", "increase"});
  expect_error(edit("{\"distribution\": \"monodisperse\", \"radius_um\": 0.2}",
                    "{\"distribution\": \"lognormal\", \"median_radius_um\": 0.2, \"sigma\": 2}"),
               {"species[0].size.sigma"});
  expect_error(edit("\"monodisperse\"", "\"gamma\""), {"species[0].size.distribution", "gamma"});
  expect_error("{\"name\": ", {"invalid JSON"});
  expect_error("[]", {"(root)"});
  // Two species whose fractions add up past close packing.
  const std::string sp = R"({"name": "a", "n": 1.0, "k": 0, "volume_fraction": 0.4,
                            "size": {"distribution": "monodisperse", "radius_um": 0.2}})";
  expect_error(edit("\"species\": [", "\"species\": [" + sp + ", " + sp + ", "),
               {"species", "add up"});
}

TEST(FiberSpec, LoadsFilesAndPresetsAndReportsMissingOnes) {
  const auto dir = weft::testing::fresh_test_dir();
  const auto path = dir / "fiber.json";
  {
    std::ofstream out(path);
    out << kMinimal;
  }
  EXPECT_EQ(load_fiber_spec(path.string()).name, "test");
  try {
    load_fiber_spec((dir / "missing.json").string());
    FAIL();
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("missing.json"), std::string::npos) << what;
    EXPECT_NE(what.find("red-cotton"), std::string::npos) << what;  // lists the presets
  }
  const auto names = fiber_preset_names();
  EXPECT_EQ(names,
            (std::vector<std::string>{"red-cotton", "white-cotton", "polyester-delustered",
                                      "polyester-filament", "silk", "acrylic", "nylon-filament"}));
  for (const auto& n : names) EXPECT_EQ(load_fiber_spec(n).name, n);
  EXPECT_THROW(fiber_preset_json("blue-silk"), Error);
}

TEST(FiberSpec, CanonicalHash) {
  const FiberSpec a = parse_fiber_spec(kMinimal, "a.json");
  // Same physics written differently: reordered keys, a renamed spec, a constant index as 33
  // values, the absorption per mm.
  std::string arr = "[";
  for (int b = 0; b < kNumBands; ++b) arr += std::string("1.5") + (b + 1 < kNumBands ? "," : "]");
  const std::string b_text = R"({
    "species": [{"size": {"radius_um": 0.2, "distribution": "monodisperse"}, "volume_fraction": 0.01,
                 "k": 0, "n": 2, "name": "other"}],
    "host": {"absorption_per_mm": 10, "n": )" +
                             arr + R"(},
    "roughness": {"alpha": 0.2, "distribution": "ggx"},
    "fiber_radius_um": 5.0, "name": "renamed", "notes": "x"})";
  const FiberSpec b = parse_fiber_spec(b_text, "b.json");
  EXPECT_EQ(fiber_spec_hash(a), fiber_spec_hash(b));
  EXPECT_EQ(canonical_json(a), canonical_json(b));
  // Any physical change changes it.
  EXPECT_NE(fiber_spec_hash(a),
            fiber_spec_hash(parse_fiber_spec(edit("0.01,", "0.011,"), "c.json")));
  EXPECT_NE(fiber_spec_hash(a),
            fiber_spec_hash(parse_fiber_spec(edit("\"ggx\"", "\"beckmann\""), "c.json")));
  EXPECT_NE(fiber_spec_hash(a),
            fiber_spec_hash(parse_fiber_spec(edit("\"k\": 0.0", "\"k\": 1e-9"), "c.json")));
  // The format is a cache key: it must not drift silently. FNV-1a 64 of kMinimal's canonical
  // dump, fixed when the format was written (recomputed independently in Python from the dump).
  EXPECT_EQ(fiber_spec_hash_hex(a), "ca8c1308b88bddf4");
}

TEST(FiberSpec, NameAndNotesAreNotPartOfTheCanonicalFormOrHash) {
  const FiberSpec a = parse_fiber_spec(kMinimal, "a.json");
  const FiberSpec renamed =
      parse_fiber_spec(edit("\"name\": \"test\"", "\"name\": \"other\""), "b.json");
  const FiberSpec noted = parse_fiber_spec(
      edit("\"name\": \"test\",", "\"name\": \"test\", \"notes\": \"dyed in 2009\","), "c.json");
  EXPECT_EQ(renamed.name, "other");
  EXPECT_EQ(canonical_json(renamed), canonical_json(a));
  EXPECT_EQ(canonical_json(noted), canonical_json(a));
  EXPECT_EQ(fiber_spec_hash_hex(renamed), fiber_spec_hash_hex(a));
  EXPECT_EQ(fiber_spec_hash_hex(noted), fiber_spec_hash_hex(a));
  const std::string canon = canonical_json(a);
  EXPECT_EQ(canon.find("\"test\""), std::string::npos) << canon;
  EXPECT_EQ(canon.find("notes"), std::string::npos) << canon;
  // Notes must be text; they are read, not ignored.
  expect_error(edit("\"name\": \"test\",", "\"name\": \"test\", \"notes\": 3,"), {"notes"});
}

TEST(FiberSpec, BoundaryOptionDefaultsToSmoothAndKeepsOldHashes) {
  const FiberSpec plain = parse_fiber_spec(kMinimal, "spec.json");
  EXPECT_EQ(plain.boundary, FiberBoundary::kSmooth);
  // Written out, the default changes nothing: specs and cached tables from before the option keep
  // their hashes.
  const FiberSpec smooth = parse_fiber_spec(
      edit("\"name\": \"test\",", "\"name\": \"test\", \"boundary\": \"smooth\","), "spec.json");
  EXPECT_EQ(smooth.boundary, FiberBoundary::kSmooth);
  EXPECT_EQ(canonical_json(smooth), canonical_json(plain));
  EXPECT_EQ(canonical_json(plain).find("boundary"), std::string::npos);
  const FiberSpec rough = parse_fiber_spec(
      edit("\"name\": \"test\",", "\"name\": \"test\", \"boundary\": \"rough-dielectric\","),
      "spec.json");
  EXPECT_EQ(rough.boundary, FiberBoundary::kRoughDielectric);
  EXPECT_NE(fiber_spec_hash(rough), fiber_spec_hash(plain));
  EXPECT_NE(canonical_json(rough).find("\"boundary\":\"rough-dielectric\""), std::string::npos);
  // A bad value names the file, the field and the valid values.
  expect_error(edit("\"name\": \"test\",", "\"name\": \"test\", \"boundary\": \"rough\","),
               {"boundary", "rough-dielectric", "smooth"});
  expect_error(edit("\"name\": \"test\",", "\"name\": \"test\", \"boundary\": 3,"), {"boundary"});
}

TEST(FiberSpec, DensityIsOptionalCheckedAndNotHashed) {
  const FiberSpec without = parse_fiber_spec(kMinimal, "spec.json");
  EXPECT_EQ(without.density_g_cm3, 0);  // not given
  const FiberSpec with = parse_fiber_spec(
      edit("\"fiber_radius_um\": 5,", "\"fiber_radius_um\": 5, \"density_g_cm3\": 1.38,"),
      "spec.json");
  EXPECT_EQ(with.density_g_cm3, 1.38);
  // No optics depend on it: the hash (and so the bake cache) is the same.
  EXPECT_EQ(fiber_spec_hash(with), fiber_spec_hash(without));
  expect_error(edit("\"fiber_radius_um\": 5,", "\"fiber_radius_um\": 5, \"density_g_cm3\": 0,"),
               {"density_g_cm3"});
  // The presets the nonwoven and filament samples use carry their cited densities
  // (docs/presets.md): PET 1.38, silk fibroin 1.35, acrylic 1.17, nylon 6,6 1.14 g/cm3 (Morton &
  // Hearle, Physical Properties of Textile Fibres).
  EXPECT_EQ(load_fiber_spec("polyester-filament").density_g_cm3, 1.38);
  EXPECT_EQ(load_fiber_spec("silk").density_g_cm3, 1.35);
  EXPECT_EQ(load_fiber_spec("acrylic").density_g_cm3, 1.17);
  EXPECT_EQ(load_fiber_spec("nylon-filament").density_g_cm3, 1.14);
}

TEST(FiberSpec, NylonFilamentIsPolyesterFilamentWithNylonsPhysics) {
  // nylon-filament follows polyester-filament (docs/presets.md) and changes only what nylon 6,6
  // changes. Host index: Morton & Hearle, Physical Properties of Textile Fibres, nylon 6,6
  // n_par = 1.582, n_perp = 1.519; the orientation average (n_par + 2 n_perp) / 3 = 1.54, in every
  // band, against PET's 1.60.
  const FiberSpec nylon = load_fiber_spec("nylon-filament");
  const FiberSpec pet = load_fiber_spec("polyester-filament");
  for (int b = 0; b < kNumBands; ++b) {
    EXPECT_NEAR(nylon.host_n[b], (1.582 + 2 * 1.519) / 3, 5e-4) << b;
    EXPECT_EQ(nylon.host_absorption_per_um[b], 0.0) << b;  // transparent, as PET
  }
  // The same 83 dtex f72 yarn at nylon's 1.14 g/cm3: area = 1.153e-7 kg/m / 1140 kg/m3, r =
  // sqrt(area / pi) = 5.67 um (PET's 1380 kg/m3 gives 5.16 um).
  EXPECT_NEAR(nylon.fiber_radius_um, std::sqrt(83.0 / 72 * 1e-7 / 1140 / std::numbers::pi) * 1e6,
              0.05);
  // Semi-dull, 0.3 wt % rutile: 0.003/4.2 / (0.003/4.2 + 0.997/1.14) = 0.082 vol %, written to one
  // significant digit as acrylic's 0.084 is; the particles themselves are PET's.
  ASSERT_EQ(nylon.species.size(), 1u);
  ASSERT_EQ(pet.species.size(), 1u);
  EXPECT_NEAR(nylon.species[0].volume_fraction, 0.003 / 4.2 / (0.003 / 4.2 + 0.997 / 1.14), 5e-5);
  EXPECT_EQ(nylon.species[0].n, pet.species[0].n);
  EXPECT_EQ(nylon.species[0].size.radius_um, pet.species[0].size.radius_um);
  EXPECT_EQ(nylon.species[0].size.kind, pet.species[0].size.kind);
  EXPECT_EQ(nylon.species[0].size.sigma, pet.species[0].size.sigma);
  // Surface: the same melt-spun, untextured filament (a modelling choice).
  EXPECT_EQ(nylon.roughness_distribution, pet.roughness_distribution);
  EXPECT_EQ(nylon.roughness_alpha, pet.roughness_alpha);
  EXPECT_NE(fiber_spec_hash(nylon), fiber_spec_hash(pet));
}
