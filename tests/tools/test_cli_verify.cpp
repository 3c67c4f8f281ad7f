// weft verify as a user meets it: a draft run writes the whole report folder; a bad measured
// table is refused naming the file and the column, exit code 2, nothing written; bad fit options
// are refused before any work; a baked fiber table in place of a spec; the estimate and the
// long-work rule; shards and their merge; Slurm scripts. (The fit's library:
// tests/verify/test_fit_models.cpp.)
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_run.h"
#include "test_util.h"
#include "weft/fiber/fiber_spec.h"
#include "weft/fiber/fiber_table_bake.h"
#include "weft/verify/verify.h"

namespace fs = std::filesystem;
using weft::testing::fresh_test_dir;

namespace {

using VerifyRun = weft::testing::CliRun;
using weft::testing::slurp;

VerifyRun run_weft(const std::string& args, const fs::path& dir) {
  // A python3 that fails, first on PATH: the plots must not depend on which python3 that finds.
  const fs::path bin = dir / "fakebin";
  fs::create_directories(bin);
  std::ofstream(bin / "python3") << "#!/bin/sh\nexit 1\n";
  fs::permissions(bin / "python3", fs::perms::owner_all);
  // In 'dir': the bake cache (./.weft-cache) is the test's own.
  return weft::testing::run_weft_cli(
      args, dir, "cd '" + dir.string() + "' && PATH='" + bin.string() + "':$PATH ");
}

}  // namespace

TEST(CliVerify, BadMeasuredTableNamesFileAndColumnAndWritesNothing) {
  const fs::path dir = fresh_test_dir();
  const fs::path csv = dir / "bad.csv";
  std::ofstream(csv) << "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G\n0,0,1,1\n";
  const fs::path out = dir / "report";
  const VerifyRun r = run_weft(
      "verify --quiet --quality draft --measured '" + csv.string() + "' -o '" + out.string() + "'",
      dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(csv.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nbrdf_beta_B"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A value that is not a number: the line and the column.
  std::ofstream(csv) << "theta_i_deg,theta_o_deg,nbrdf_beta_R,nbrdf_beta_G,nbrdf_beta_B\n"
                        "0,0,1,1,1\n0,5,1,oops,1\n";
  const VerifyRun r2 =
      run_weft("verify --quiet --measured '" + csv.string() + "' -o '" + out.string() + "'", dir);
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("line 3 nbrdf_beta_G"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(out));
  // A fiber table that is not there: the file and the option.
  const VerifyRun r3 = run_weft("verify --quiet --fiber x.exr -o '" + out.string() + "'", dir);
  EXPECT_EQ(r3.exit_code, 2);
  EXPECT_NE(r3.err.find("x.exr"), std::string::npos) << r3.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliVerify, DraftWritesTheWholeReport) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  const VerifyRun r =
      run_weft("verify --quiet --quality draft --threads 2 -o '" + out.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // --quiet: no estimate, progress or notes
  // One figure per incidence (tools/plot_verify.py; its layout: test_plot_verify.cpp).
  for (const char* f : {"inplane.csv", "metrics.json", "index.html", "inplane-00.0deg.png",
                        "inplane-00.0deg.svg", "inplane-70.0deg.png", "inplane-70.0deg.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto j = nlohmann::json::parse(slurp(out / "metrics.json"));
  for (const char* k : {"computed_rms_log", "classic_rms_log", "computed_rms_log_absolute",
                        "classic_rms_log_absolute"})
    EXPECT_TRUE(j.at(k).is_number()) << k;
  EXPECT_EQ(j.at("settings").at("quality"), "draft");
  // The bundled measurement's nine incidences, each scored.
  EXPECT_EQ(j.at("models").at("classic").at("per_incidence").size(), 9u);
  const std::string html = slurp(out / "index.html");
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("real fabric (paper, Table 1)"), std::string::npos);
  // Each fabric table's preview page beside the report, linked (where three.js is installed).
  if (fs::exists(fs::path(WEFT_SOURCE_DIR) /
                 "exchange/viewer/node_modules/three/build/three.module.min.js"))
    for (const char* p : {"preview-computed.html", "preview-classic.html"}) {
      EXPECT_TRUE(fs::exists(out / p)) << p;
      EXPECT_NE(html.find(std::string("<a href=\"") + p + "\">"), std::string::npos) << p;
    }
  else
    EXPECT_NE(html.find("No 3-D previews"), std::string::npos);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
  // The renders (paper's Figs. 8-9): computed and classic in both configurations, the measured
  // BRDF in reflection, EXR and PNG, linked from the page by relative path (readable offline).
  std::map<std::string, weft::Rgb> patch, mean;
  const auto rgb = [](const nlohmann::json& c) {
    return weft::Rgb(c[0].get<double>(), c[1].get<double>(), c[2].get<double>());
  };
  for (const auto& v : j.at("renders")) {
    const std::string png = v.at("png");
    const std::string stem = png.substr(0, png.size() - 4);
    EXPECT_EQ(v.at("exr"), stem + ".exr");
    mean[stem] = rgb(v.at("mean_linear_srgb"));
    if (v.at("kind") == "patch") patch[stem] = rgb(v.at("patch_radiance_linear_srgb"));
  }
  // A render is listed with its colour, written as EXR and PNG, and shown on the page.
  const auto expect_render = [&](const char* stem, const std::map<std::string, weft::Rgb>& rgb) {
    ASSERT_EQ(rgb.count(stem), 1u) << stem;
    for (const char* ext : {".exr", ".png"})
      EXPECT_TRUE(fs::exists(out / (std::string(stem) + ext))) << stem << ext;
    EXPECT_NE(html.find(std::string("src=\"") + stem + ".png\""), std::string::npos) << stem;
    EXPECT_GT(rgb.at(stem).r, 0) << stem;
  };
  for (const char* stem :
       {"render-reflection-computed", "render-transmission-computed", "render-reflection-classic",
        "render-transmission-classic", "render-reflection-measured"})
    expect_render(stem, patch);
  // Lit from behind, the computed fabric is less saturated (purpler) than lit from the front: its
  // G/R and B/R are larger, and they must be larger in the render exactly when the colour table
  // (directional reflectance and transmittance at normal incidence, from the same fabric table)
  // says so: the renders show the table the colour table describes.
  std::map<std::string, weft::Rgb> colour;
  for (const auto& c : j.at("colour_table"))
    if (c.contains("linear_srgb"))
      colour[c.at("name")] =
          weft::Rgb(c.at("linear_srgb")[0].get<double>(), c.at("linear_srgb")[1].get<double>(),
                    c.at("linear_srgb")[2].get<double>());
  const weft::Rgb cr = colour.at("computed fabric, reflection");
  const weft::Rgb ct = colour.at("computed fabric, transmission");
  const weft::Rgb rr = patch["render-reflection-computed"];
  const weft::Rgb rt = patch["render-transmission-computed"];
  EXPECT_EQ(rt.g / rt.r > rr.g / rr.r, ct.g / ct.r > cr.g / cr.r);
  EXPECT_EQ(rt.b / rt.r > rr.b / rr.r, ct.b / ct.r > cr.b / cr.r);
  EXPECT_GT(rt.g / rt.r, rr.g / rr.r);  // the paper's "purple to dark red" (its Table 1)
  // The fiber-level renders: the fibers of the sample with each model's fiber table, both
  // configurations, beside the others and linked the same way.
  for (const char* stem : {"render-weave-reflection-computed", "render-weave-transmission-computed",
                           "render-weave-reflection-classic", "render-weave-transmission-classic"})
    expect_render(stem, mean);
  for (const char* model : {"computed", "classic"})
    EXPECT_TRUE(fs::exists(out / (std::string("fiber-") + model + ".exr"))) << model;
  // Over whole repeats the fiber-level render's mean is the cloth's radiance for its view and
  // light, which the patch shows through the ray-traced fabric table of the same fibers: for the
  // classic fiber, whose cloth's BRDF is smooth, they agree (measured: within 0.3 % in red; 10 %
  // leaves room for the draft table's noise). In transmission the opaque classic fibers pass only
  // what they scatter off the beam (measured: 0.045 of the reflection in red); the table's patch
  // also holds the beam passing straight through the gaps, spread over its cell (docs/verify.md).
  EXPECT_NEAR(mean["render-weave-reflection-classic"].r, patch["render-reflection-classic"].r,
              0.1 * patch["render-reflection-classic"].r);
  EXPECT_LT(mean["render-weave-transmission-classic"].r,
            0.2 * mean["render-weave-reflection-classic"].r);
  // A second run into a folder that holds something else is refused, and the folder kept.
  const fs::path other = dir / "other";
  fs::create_directories(other);
  std::ofstream(other / "notes.txt") << "mine";
  const VerifyRun r2 = run_weft("verify --quiet --quality draft -o '" + other.string() + "'", dir);
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("refusing"), std::string::npos) << r2.err;
  EXPECT_TRUE(fs::exists(other / "notes.txt"));
}

// Bad fit options are refused before any work, naming the option, exit 2, nothing written (the
// library's own refusals: tests/verify/test_fit_models.cpp).
TEST(CliVerify, BadFitOptionsAreRefusedBeforeAnyWork) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  // A fiber without particles: nothing for the particle parameters to scale.
  auto bare = nlohmann::json::parse(weft::fiber_preset_json("red-cotton"));
  bare["species"] = nlohmann::json::array();
  const fs::path bare_spec = dir / "bare.json";
  std::ofstream(bare_spec) << bare.dump();
  struct Case {
    std::string args, field, words;
  };
  const std::vector<Case> cases = {
      {"--fit --fit-params dye_scale,colour", "--fit-params", "'colour' is not one of"},
      {"--fit --fit-params dye_scale,dye_scale", "--fit-params", "named twice"},
      {"--fit --fit-params dye_scale,", "--fit-params", "an empty name"},
      {"--fit --fit-evaluations 5", "--fit-evaluations", "fewer than 2 p + 2"},
      {"--fit-params dye_scale", "--fit-params", "only with --fit"},
      {"--fit --fit-inner exact", "--fit-inner", "not raytrace or summation"},
      {"--fit-inner summation", "--fit-inner", "only with --fit"},
      {"--fit --fit-method newton", "--fit-method", "not lm or nelder-mead"},
      {"--fit-method nelder-mead", "--fit-method", "only with --fit"},
      {"--fit --fit-seeds 0", "--fit-seeds", "outside 1 to 16"},
      {"--fit --fit-seeds 17", "--fit-seeds", "outside 1 to 16"},
      {"--fit-seeds 2", "--fit-seeds", "only with --fit"},
      {"--fit --fiber '" + bare_spec.string() + "' --fit-params particle_radius_scale",
       "--fit-params", "the spec has no particle species"}};
  for (const auto& c : cases) {
    const VerifyRun r =
        run_weft("verify --quiet --quality draft " + c.args + " -o '" + out.string() + "'", dir);
    EXPECT_EQ(r.exit_code, 2) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.field), std::string::npos) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

namespace {

// A small red-cotton fiber table as weft bake fiber makes it (R = 3 keeps the verify run short:
// the ray trace's cost grows with the incident bins, R^2), and the bake's per-band summary.
weft::FiberTableBakeResult small_red_cotton_bake() {
  weft::FiberTableBakeOptions b;
  b.resolution = 3;
  b.photons_per_band = 20000;
  b.seed = 3;
  b.spectral = true;
  return weft::bake_fiber_table(weft::load_fiber_spec("red-cotton"), b);
}

// metrics.json without its timings ("seconds": wall-clock times of the steps, which differ from
// run to run), as text.
std::string metrics_without_seconds(const fs::path& report) {
  auto j = nlohmann::json::parse(slurp(report / "metrics.json"));
  EXPECT_TRUE(j.contains("seconds"));
  j.erase("seconds");
  return j.dump(1);
}

}  // namespace

// --fiber TABLE: the classic baseline's colour from the table alone. Its total albedo is the
// walks' exit fraction (the bake's own energy_table check), so the table's albedo minus the
// classic Cook-Torrance lobe's must equal the spec path's volume albedo, exit - surface, up to the
// difference between the lobe's albedo (0.0729 for this Beckmann 0.35 surface of index 1.557,
// docs/verify.md) and the bake's surface fraction of the same surface, whose standard error at
// 20 000 photons per band is sqrt(0.073 x 0.927 / 20000) = 0.0018: 0.0065 per band is 3.5 of
// them. A band offset common to all bands moves each linear sRGB channel by about the same (D65
// white is (1, 1, 1) within 1.2e-3, core/spectrum.h), so the same 0.0065 per channel. Then the
// whole command runs on the table, with the derived colour and with --classic-albedo.
TEST(CliVerify, FiberTableGivesTheClassicColourFromItsAlbedo) {
  const fs::path dir = fresh_test_dir();
  const weft::FiberTableBakeResult bake = small_red_cotton_bake();
  const fs::path table = dir / "fiber.exr";
  bake.table.write_exr(table);
  const auto derived = weft::classic_diffuse_from_fiber_table(
      bake.table, {weft::MicrofacetModel::kBeckmann, 0.35}, 1.557, 1, 0);
  weft::Spectrum volume{};
  for (const auto& band : bake.bands) {
    volume[band.band] = band.walk_exit_fraction() - band.surface_fraction;
    EXPECT_NEAR(derived[band.band], volume[band.band], 0.0065) << "band " << band.band;
  }
  // The classic reflectance is the volume albedo over the share past the lobe (classic.h), and
  // the band tolerance scales with it.
  const double entering =
      weft::classic_entering_fraction({weft::MicrofacetModel::kBeckmann, 0.35}, 1.557);
  const double tol = 0.0065 / entering;
  weft::Rgb want = weft::bands_to_linear_srgb([&](int b) { return volume[b] / entering; });
  weft::GamutClip clip;
  clip.clip(want);

  const fs::path out = dir / "report";
  const VerifyRun r = run_weft("verify --quiet --quality draft --threads 2 --fiber '" +
                                   table.string() + "' -o '" + out.string() + "'",
                               dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(out / "metrics.json"));
  EXPECT_EQ(j.at("fiber"), table.string());
  EXPECT_EQ(j.at("settings").at("resolution"), 3);  // the table's
  const std::string source = j.at("classic_source");
  EXPECT_NE(source.find("total albedo"), std::string::npos) << source;
  EXPECT_NE(source.find("preset red-cotton"), std::string::npos) << source;
  const auto& c = j.at("classic_reflectance_linear_srgb");
  EXPECT_NEAR(c[0].get<double>(), want.r, tol);
  EXPECT_NEAR(c[1].get<double>(), want.g, tol);
  EXPECT_NEAR(c[2].get<double>(), want.b, tol);
  EXPECT_TRUE(fs::exists(out / "render-transmission-classic.png"));

  // An explicit colour is used as given.
  const VerifyRun r2 =
      run_weft("verify --quiet --quality draft --threads 2 --fiber '" + table.string() +
                   "' --classic-albedo 0.3,0.05,0.03 -o '" + out.string() + "'",
               dir);
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  const auto j2 = nlohmann::json::parse(slurp(out / "metrics.json"));
  EXPECT_EQ(j2.at("classic_reflectance_linear_srgb"), nlohmann::json({0.3, 0.05, 0.03}));
  EXPECT_NE(j2.at("classic_source").get<std::string>().find("--classic-albedo"), std::string::npos);
}

// Bad tables and options are refused before any work, naming the file (and the field), exit 2,
// nothing written.
TEST(CliVerify, BadFiberTablesAreRefusedNamingTheFile) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  weft::TabulatedBsdfTable good = small_red_cotton_bake().table;
  const fs::path table = dir / "fiber.exr";
  good.write_exr(table);
  auto refused = [&](const std::string& args, const std::vector<std::string>& words) {
    const VerifyRun r =
        run_weft("verify --quiet --quality draft " + args + " -o '" + out.string() + "'", dir);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    for (const auto& w : words) EXPECT_NE(r.err.find(w), std::string::npos) << w << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  };
  // Truncated: the first half of a good file.
  const std::string bytes = slurp(table);
  const fs::path cut = dir / "cut.exr";
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  refused("--fiber '" + cut.string() + "'", {cut.string(), "--fiber"});
  // Not an EXR at all.
  const fs::path text = dir / "text.exr";
  std::ofstream(text) << "not a table";
  refused("--fiber '" + text.string() + "'", {text.string(), "--fiber"});
  // A fabric table.
  weft::TabulatedBsdfTable fabric = good;
  fabric.kind = "fabric";
  const fs::path fabric_file = dir / "fabric.exr";
  fabric.write_exr(fabric_file);
  refused("--fiber '" + fabric_file.string() + "'", {fabric_file.string(), "fabric table"});
  // No roughness in the header: the classic baseline cannot be made.
  weft::TabulatedBsdfTable bare = good;
  bare.metadata.erase("roughness");
  const fs::path bare_file = dir / "bare.exr";
  bare.write_exr(bare_file);
  refused("--fiber '" + bare_file.string() + "'", {bare_file.string(), "roughness"});
  // A fiber darker than its own surface: no diffuse colour follows; the error asks for one.
  weft::TabulatedBsdfTable dark = good;
  for (float& v : dark.values) v *= 0.05f;
  const fs::path dark_file = dir / "dark.exr";
  dark.write_exr(dark_file);
  refused("--fiber '" + dark_file.string() + "'", {dark_file.string(), "--classic-albedo R,G,B"});
  // The fit needs a spec; the colour must be three reflectances.
  refused("--fit --fiber '" + table.string() + "'", {table.string(), "--fit"});
  refused("--fiber '" + table.string() + "' --classic-albedo 2,0,0", {"--classic-albedo"});
  refused("--classic-albedo 0.3,0.2", {"--classic-albedo"});
}

// The estimate comes first, then the refusal of work above an hour at the fastest rates (the
// long-work rule of docs/ARCHITECTURE.md): 60 000 fit evaluations per model on one thread are at
// least 60 009 inner bakes x 165 000 photons x 0.5 us = 1.4 h of CPU (the inner ray traces are one
// per search stage, their paths re-weighted per evaluation: plan.cpp counts 8 x 144 000 particles).
TEST(CliVerify, PrintsItsEstimateAndRefusesLongWorkWithoutYesLong) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "report";
  const VerifyRun r = run_weft(
      "verify --quality draft --threads 1 --fit --fit-evaluations 60000 -o '" + out.string() + "'",
      dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("weft verify: quality draft with --fit"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("M particles: about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--yes-long"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// verify split over processes: three shards of its ray traces (incident bins of every batch of
// both models) and `weft merge` make the report of the one-process run: inplane.csv byte for byte,
// metrics.json but for its timings (energy books and noise included). The fiber bake the shards
// share is baked once, into the bake cache, and reused by the other shards and the merge.
TEST(CliVerify, ShardsMergeToTheOneProcessReport) {
  const fs::path dir = fresh_test_dir();
  const std::string common = "verify --quiet --quality draft --threads 2 ";
  const fs::path one = dir / "one";
  VerifyRun r = run_weft(common + "-o '" + one.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  fs::remove_all(dir / ".weft-cache");  // the shards bake it again, once

  std::string parts;
  for (int k = 0; k < 3; ++k) {
    const fs::path part = dir / ("part-" + std::to_string(k) + ".part");
    r = run_weft(common + "--shard " + std::to_string(k) + "/3 -o '" + part.string() + "'", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("shard " + std::to_string(k) + "/3"), std::string::npos) << r.out;
    parts = "'" + part.string() + "' " + parts;  // any order
  }
  size_t cached = 0;
  for (const auto& e : fs::directory_iterator(dir / ".weft-cache"))
    cached += e.path().extension() == ".exr";
  EXPECT_EQ(cached, 1u);  // one spectral fiber table for all three shards

  const fs::path merged = dir / "merged";
  r = run_weft("merge " + parts + "-o '" + merged.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string a = slurp(one / "inplane.csv"), b = slurp(merged / "inplane.csv");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "inplane.csv differs";
  EXPECT_EQ(metrics_without_seconds(one), metrics_without_seconds(merged));
  // The renders are made by the merge from the same tables and seed: the same images.
  for (const char* stem : {"render-reflection-computed", "render-weave-reflection-computed",
                           "render-weave-transmission-classic"})
    EXPECT_TRUE(slurp(one / (std::string(stem) + ".exr")) ==
                slurp(merged / (std::string(stem) + ".exr")))
        << stem;

  // A missing shard is named; --fit is refused with --shard.
  r = run_weft("merge '" + (dir / "part-0.part").string() + "' '" + (dir / "part-2.part").string() +
                   "' -o '" + (dir / "m2").string() + "'",
               dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing shard 1/3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "m2"));
  r = run_weft(common + "--fit --shard 0/2 -o '" + (dir / "p.part").string() + "'", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--fit"), std::string::npos) << r.err;
}

// weft slurm verify --dry-run: the array script runs verify's shards (without --resume, which
// verify does not have) into parts beside the report, and the merge script merges all of them
// into the report folder; nothing is submitted or written.
TEST(CliVerify, SlurmDryRunScripts) {
  const fs::path dir = fresh_test_dir();
  const fs::path report = dir / "report";
  const VerifyRun r = run_weft(
      "slurm --shards 4 --partition cpu --time 1:00:00 --dry-run verify "
      "--quality draft -o '" +
          report.string() + "'",
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string slurm = report.string() + ".slurm";
  for (const std::string& s :
       {std::string("#SBATCH --array=0-3"), std::string("#SBATCH --partition=cpu"),
        std::string("#SBATCH --time=1:00:00"),
        std::string("'verify' '--quality' 'draft' '-o' '") + slurm +
            "/part-'\"$SLURM_ARRAY_TASK_ID\".part",
        std::string("--shard \"$SLURM_ARRAY_TASK_ID/4\" --quiet\n"),
        std::string("merge '") + slurm + "/part-0.part' '" + slurm + "/part-1.part' '" + slurm +
            "/part-2.part' '" + slurm + "/part-3.part' -o '" + report.string() + "'",
        std::string("sbatch --dependency=afterok:")})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  EXPECT_EQ(r.out.find("--resume"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(slurm));
  EXPECT_FALSE(fs::exists(report));
  // --fit cannot run as shards.
  const VerifyRun fit =
      run_weft("slurm --shards 2 --dry-run verify --fit -o '" + report.string() + "'", dir);
  EXPECT_EQ(fit.exit_code, 2);
  EXPECT_NE(fit.err.find("--fit"), std::string::npos) << fit.err;
}

// --suite: every fabric of a suite file planned before any work (one bad fabric refuses the
// whole suite and writes nothing), a report per fabric, and the page over them whose rows are
// the reports' own figures; options the suite sets per fabric are refused with it.
TEST(CliVerify, SuiteWritesAReportPerFabricAndOnePage) {
  const fs::path dir = fresh_test_dir();
  const std::string src = WEFT_SOURCE_DIR;
  const auto fabric = [&](const std::string& name, const std::string& weave) {
    return "{\"name\": \"" + name + "\", \"measured\": \"" + src +
           "/materials/data/measured/merl-white-fabric/inplane.csv\", \"fiber\": "
           "\"white-cotton\", \"weave\": \"" +
           weave + "\", \"colour_space\": \"camera\", \"known\": \"a white cloth\"}";
  };
  const std::string poplin = src + "/scenes/examples/red-cotton-weave.json";
  std::ofstream(dir / "bad.json") << "{\"title\": \"t\", \"fabrics\": [" << fabric("a", poplin)
                                  << ", " << fabric("b", (dir / "none.json").string()) << "]}";
  const fs::path out = dir / "suite";
  VerifyRun r = run_weft("verify --quiet --quality draft --suite-file bad.json -o suite", dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("none.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run_weft("verify --quiet --quality draft --suite --measured x.csv -o suite", dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--measured"), std::string::npos) << r.err;
  // The suite file states each measurement's colour space: one given for all would be dropped.
  r = run_weft("verify --quiet --quality draft --suite --colour-space srgb -o suite", dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--colour-space"), std::string::npos) << r.err;

  // Two fabrics of the same weave options: the second is handed the first's woven sample, made
  // once (its seconds are the hand-over's), and its report is the one a sample of its own gives.
  std::ofstream(dir / "one.json") << "{\"title\": \"one\", \"fabrics\": [" << fabric("w", poplin)
                                  << ", " << fabric("v", poplin) << "]}";
  r = run_weft("verify --quiet --quality draft --threads 2 --suite-file one.json -o suite", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto s = nlohmann::json::parse(slurp(out / "suite.json"));
  EXPECT_EQ(s.at("report"), "weft verify suite");
  ASSERT_EQ(s.at("fabrics").size(), 2u);
  const auto m = nlohmann::json::parse(slurp(out / "w" / "metrics.json"));
  EXPECT_EQ(s.at("fabrics")[0].at("models").at("classic").at("paper_rms_log"),
            m.at("models").at("classic").at("normalized").at("rms_log"));
  const auto mv = nlohmann::json::parse(slurp(out / "v" / "metrics.json"));
  EXPECT_EQ(mv.at("models"), m.at("models"));
  EXPECT_LT(mv.at("seconds").at("woven_sample").get<double>(),
            0.25 * m.at("seconds").at("woven_sample").get<double>());
  EXPECT_NE(slurp(out / "index.html").find("w/index.html"), std::string::npos);
  EXPECT_NE(r.out.find("w "), std::string::npos) << r.out;
  // Anything but an earlier suite is refused and left alone.
  fs::create_directories(dir / "other");
  std::ofstream(dir / "other" / "x") << "keep";
  r = run_weft("verify --quiet --quality draft --suite-file one.json -o other", dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(slurp(dir / "other" / "x"), "keep");
}
