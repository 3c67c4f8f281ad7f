// The weft program as a user meets it: bad input gives a clear error naming the file and field,
// a non-zero exit and no output file; good input gives the promised JSON and a valid table;
// Ctrl-C leaves either a complete table or none.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>

#include "cli_run.h"
#include "test_util.h"
#include "weft/core/math.h"
#include "weft/materials/bsdf_table.h"

namespace fs = std::filesystem;
// Each test works in its own folder under the build folder (fresh_test_dir), not in the shared
// temporary folder, where another build's tests running at the same time would use the same names.
using namespace weft::testing;

namespace {

// Runs 'args' with '-o output' and expects a refusal: exit code 2, an error that mentions 'part',
// and nothing at 'output'. Returns the run for more checks of its message.
CliRun expect_refused(const std::string& args, const fs::path& output, const std::string& part,
                      const fs::path& dir) {
  const CliRun r = run_weft_cli(args + " -o '" + output.string() + "'", dir);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(part), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(output));
  return r;
}

// Outputs are written atomically: no temporary (".tmp-*") may be left in 'dir'.
void expect_no_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

const char* kGoodSpec = R"({"name": "cli-test", "fiber_radius_um": 6,
  "roughness": {"distribution": "beckmann", "alpha": 0.3},
  "host": {"n": 1.557},
  "species": [{"name": "voids", "n": 1.0, "k": 0.0, "volume_fraction": 0.02,
               "size": {"distribution": "monodisperse", "radius_um": 0.3}}]})";

}  // namespace

TEST(Cli, BakeFiberWritesTableAndJsonSummary) {
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "fiber.exr";
  const CliRun r = run_weft_cli(
      "bake fiber red-cotton --photons 60 --resolution 2 --passes 2 --json --quiet -o '" +
          out.string() + "'",
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"photons", "scattering_events", "events_per_s", "per_band", "spec_hash"})
    EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_EQ(j["per_band"].size(), 33u);
  for (const auto& b : j["per_band"]) {
    EXPECT_TRUE(b.contains("albedo"));
    EXPECT_NEAR(b["energy_balance"].get<double>(), 1.0, 1e-9);
  }
  const auto table = weft::TabulatedBsdfTable::read_exr(out);
  EXPECT_EQ(table.resolution, 2);
  EXPECT_EQ(table.channels, 33);
  EXPECT_EQ(table.metadata.at("spec_hash"), j["spec_hash"].get<std::string>());
  EXPECT_EQ(table.metadata.at("photons"), "60");
  EXPECT_EQ(table.metadata.at("seed"), "1");
  EXPECT_TRUE(table.metadata.count("program_version"));
}

TEST(Cli, BadSpecsNameTheFieldExitNonZeroAndWriteNothing) {
  const fs::path dir = fresh_test_dir();
  struct Case {
    std::string name, text, expect_in_error;
  };
  std::string good = kGoodSpec;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  const std::vector<Case> cases = {
      {"negative-radius", with("\"fiber_radius_um\": 6", "\"fiber_radius_um\": -6"),
       "fiber_radius_um"},
      {"packed-too-dense", with("\"volume_fraction\": 0.02", "\"volume_fraction\": 0.8"),
       "volume_fraction"},
      {"unknown-key", with("\"name\": \"cli-test\"", "\"name\": \"cli-test\", \"colour\": 1"),
       "colour"},
      {"nan", with("\"alpha\": 0.3", "\"alpha\": NaN"), ""},
      {"truncated", good.substr(0, good.size() / 2), ""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path spec = dir / (c.name + ".json");
    write_file(spec, c.text);
    const CliRun r = expect_refused("bake fiber '" + spec.string() + "' --photons 10 --quiet",
                                    dir / (c.name + ".exr"), spec.filename().string(), dir);
    if (!c.expect_in_error.empty()) {
      EXPECT_NE(r.err.find(c.expect_in_error), std::string::npos) << r.err;
    }
  }
  // A missing file is named, and the presets are listed.
  const CliRun missing = expect_refused("bake fiber '" + (dir / "nope.json").string() + "'",
                                        dir / "x.exr", "nope.json", dir);
  EXPECT_NE(missing.err.find("red-cotton"), std::string::npos) << missing.err;
  // Leftover temporaries would be half-written outputs.
  expect_no_temporaries(dir);
}

TEST(Cli, BadNumbersOnTheCommandLineAreRejected) {
  const fs::path dir = fresh_test_dir();
  EXPECT_NE(run_weft_cli(
                "bake fiber red-cotton --resolution 1 -o '" + (dir / "a.exr").string() + "'", dir)
                .exit_code,
            0);
  EXPECT_NE(
      run_weft_cli("bake fiber red-cotton --photons 0 -o '" + (dir / "b.exr").string() + "'", dir)
          .exit_code,
      0);
  EXPECT_NE(
      run_weft_cli("bake fiber red-cotton --bands xyz -o '" + (dir / "c.exr").string() + "'", dir)
          .exit_code,
      0);
  EXPECT_FALSE(fs::exists(dir / "a.exr"));
  const CliRun mie = run_weft_cli("mie --m-re nan --m-im 0 --x 10 --json", dir);
  EXPECT_EQ(mie.exit_code, 2) << mie.err;
  const CliRun slab = run_weft_cli(
      "slab --mua-per-mm -1 --mus-per-mm 10 --g 0.9 --n-slab 1.4 --thickness-mm 1 "
      "--photons 10 --seed 1 --json",
      dir);
  EXPECT_NE(slab.exit_code, 0);
  EXPECT_NE(slab.err.find("mua"), std::string::npos) << slab.err;
}

TEST(Cli, InterruptedBakeLeavesACompleteTableOrNone) {
  // SIGINT after 2 s into a long bake of many short passes: the program stops at a task
  // boundary and writes the finished passes (exit 130, metadata "interrupted"), or, if not even
  // one pass finished, writes nothing (exit 2), or, stopped before any photon (in the Mie/medium
  // stage, before the work polls, or before the handler is installed on a loaded machine, when
  // the default action ends it), writes nothing (exit 130). Never a partial file. timeout
  // --foreground signals the program alone: without it timeout also signals its process group,
  // so the program got SIGINT twice and, as a second Ctrl-C does, stopped at once (seen in CI).
  const fs::path dir = fresh_test_dir();
  const fs::path out = dir / "fiber.exr";
  const CliRun r = run_weft_cli(
      "bake fiber white-cotton --photons 100000000 --passes 100000 --resolution 2 --quiet -o '" +
          out.string() + "'",
      dir, "timeout --foreground --preserve-status -s INT 2 ");
  if (r.exit_code == 130 && r.err.find("wrote the finished passes") != std::string::npos) {
    const auto table = weft::TabulatedBsdfTable::read_exr(out);
    EXPECT_EQ(table.metadata.at("interrupted"), "yes");
    EXPECT_GT(std::stoull(table.metadata.at("photons")), 0u);
  } else if (r.exit_code == 130) {
    EXPECT_FALSE(fs::exists(out)) << r.err;
  } else {
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  expect_no_temporaries(dir);
}

TEST(Cli, TableInfoReportsTheAlbedoForLightFromTheNormal) {
  // A Lambert table of reflectance 0.5: light from the normal is reflected, nothing transmitted.
  // The figures are the library's (TabulatedBsdfTable::directional_albedo), printed per channel.
  const fs::path dir = fresh_test_dir();
  const fs::path table = dir / "lambert.exr";
  const CliRun bake = run_weft_cli(
      "table bake lambert --params '{\"reflectance\": 0.5}' -R 8 --spp 4 "
      "--quiet -o '" +
          table.string() + "'",
      dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.err;
  const CliRun info = run_weft_cli("table info --json '" + table.string() + "'", dir);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  const auto t = weft::TabulatedBsdfTable::read_exr(table);
  const auto normal = t.directional_albedo(t.grid().bin_of({0, 0, 1}));
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(j["albedo_normal_incidence"][c].get<double>(), normal.total(c));
    EXPECT_EQ(j["reflectance_normal_incidence"][c].get<double>(), normal.reflectance[c]);
    EXPECT_EQ(j["transmittance_normal_incidence"][c].get<double>(), normal.transmittance[c]);
  }
  // Reflected, not transmitted: at R = 8 the exit bins straddling the horizon can shift at most
  // 0.5 / pi times their projected solid angle on one side (0.245 sr) between the two: 0.039.
  EXPECT_GT(normal.reflectance[0], 10 * normal.transmittance[0]);
  // Seen along the normal (the renderer's reading): the same for this reciprocal table.
  const auto view = t.directional_albedo_seen_from(t.grid().bin_of({0, 0, 1}));
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(j["reflectance_normal_view"][c].get<double>(), view.reflectance[c]);
    EXPECT_EQ(j["transmittance_normal_view"][c].get<double>(), view.transmittance[c]);
  }
}

TEST(Cli, BakeFabricSummationReportsTheTransmittanceSeenFromAbove) {
  // A fiber table like the baked ones: light leaves only through B (f = 0 for w_o below B's
  // horizon); it reflects 0.25 and passes 0.6 of the light from behind B (analytic, constant per
  // side, so the cell averages are exact). The paper's sum puts the fiber on top of the cloth:
  // light from above is never transmitted (transmittance_normal_incidence is 0, which it
  // reported alone before), while a view from above sees 0.6 of uniform light from below.
  const fs::path dir = fresh_test_dir();
  auto fiber = weft::TabulatedBsdfTable::from_function(
      4, 3,
      [](const weft::Vec3& wo, const weft::Vec3& wi, std::span<double> v) {
        const double f = wo.z > 0 ? (wi.z > 0 ? 0.25 : 0.6) / 3.141592653589793 : 0.0;
        v[0] = v[1] = v[2] = f;
      },
      2, 1);
  fiber.kind = "fiber";
  fiber.write_exr(dir / "fiber.exr");
  const CliRun r = run_weft_cli(
      "bake fabric --method summation -R 4 --samples 2 --quiet --json --fiber '" +
          (dir / "fiber.exr").string() + "' -o '" + (dir / "fabric.exr").string() + "'",
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(j["reflectance_normal_incidence"][c].get<double>(), 0.25, 1e-6);
    EXPECT_EQ(j["transmittance_normal_incidence"][c].get<double>(), 0.0);
    EXPECT_NEAR(j["reflectance_normal_view"][c].get<double>(), 0.25, 1e-6);
    EXPECT_NEAR(j["transmittance_normal_view"][c].get<double>(), 0.6, 1e-6);
  }
}

TEST(Cli, MieRangeErrorsNameTheField) {
  // Ranges are checked by the Mie library (mie.h), whose errors name the field; the command only
  // parses its options.
  const fs::path dir = fresh_test_dir();
  struct Case {
    std::string args, field;
  };
  const Case cases[] = {
      {"--m-re 1.5 --x 2e7", "'x'"},
      {"--m-re -1.5 --x 1", "'m'"},
      {"--m-re 1.5 --m-im -0.1 --x 1", "'m'"},
      {"--particle-n 1.5 --host-n 0 --radius-um 0.3 --wavelength-nm 550", "'host_n'"},
      {"--particle-n 1.5 --host-n 1 --radius-um 0.3 --wavelength-nm 550 --lognormal-sigma 2",
       "sigma"},
      {"--x 1", "'--m-re'"},  // required with --x: the command's own rule
  };
  for (const auto& c : cases) {
    const CliRun r = run_weft_cli("mie " + c.args + " --json", dir);
    EXPECT_EQ(r.exit_code, 2) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.field), std::string::npos) << c.args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args;
  }
}

TEST(Cli, WeaveWritesSamplesAndRefusesBadInput) {
  const fs::path dir = fresh_test_dir();
  // Defaults (the bundled red-cotton poplin), fiber detail, JSON summary.
  const CliRun fib = run_weft_cli(
      "weave --detail fiber --repeats 2x1 --json -o '" + (dir / "f.glb").string() + "'", dir);
  ASSERT_EQ(fib.exit_code, 0) << fib.err;
  const auto j = nlohmann::json::parse(fib.out);
  EXPECT_EQ(j["detail"], "fiber");
  EXPECT_GT(j["curves"].get<int>(), 0);
  EXPECT_NEAR(j["period_mm"]["x"].get<double>(), 2 * 2 * 0.4233, 1e-9);  // 2 picks x 2 repeats
  EXPECT_GE(j["min_fiber_distance_um"].get<double>(), 16 * 0.99);
  EXPECT_TRUE(fs::exists(dir / "f.glb"));
  // The legacy options still make the open patch.
  const CliRun legacy = run_weft_cli(
      "weave --yarns 2 --segments 8 --sides 4 -o '" + (dir / "l.gltf").string() + "'", dir);
  EXPECT_EQ(legacy.exit_code, 0) << legacy.err;
  expect_refused("weave --yarns 2 --detail fiber", dir / "m.gltf", "detail", dir);
  // A malformed draft: error naming file, section and key; non-zero exit; nothing written.
  write_file(dir / "bad.wif",
             "[WEAVING]\nShafts=2\nTreadles=2\n[WARP]\nThreads=2\n[WEFT]\nThreads=2\n"
             "[THREADING]\n1=1\n2=3\n[TIEUP]\n1=1\n2=2\n[TREADLING]\n1=1\n2=2\n");
  const CliRun bad = expect_refused("weave --wif '" + (dir / "bad.wif").string() + "'",
                                    dir / "b.glb", "bad.wif", dir);
  EXPECT_NE(bad.err.find("[THREADING] 2"), std::string::npos) << bad.err;
  // Sizes: a yarn wider than its spacing, absurd repeats.
  expect_refused("weave --yarn-width-mm 0.5", dir / "w.glb", "warp-width-mm", dir);
  expect_refused("weave --repeats 1000x1000", dir / "h.glb", "repeats", dir);
  expect_no_temporaries(dir);
}

TEST(Cli, SceneCarSeatWritesTheSeatAndRefusesBadInput) {
  const fs::path dir = fresh_test_dir();
  const CliRun r = run_weft_cli(
      "scene car-seat --cell-mm 20 --json -o '" + (dir / "seat.glb").string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["scene"], "car-seat");
  size_t sum = 0;
  for (const auto& p : j["parts"]) sum += p["triangles"].get<size_t>();
  EXPECT_EQ(j["triangles"].get<size_t>(), sum);
  EXPECT_GT(sum, 0u);
  EXPECT_TRUE(fs::exists(dir / "seat.glb"));
  expect_refused("scene car-seat", dir / "seat.obj", "must end in .gltf or .glb", dir);
  const CliRun small =
      run_weft_cli("scene car-seat --cell-mm 0.5 -o '" + (dir / "s.glb").string() + "'", dir);
  EXPECT_NE(small.exit_code, 0);
  EXPECT_NE(small.err.find("cell-mm"), std::string::npos) << small.err;
  EXPECT_FALSE(fs::exists(dir / "s.glb"));
  expect_no_temporaries(dir);
}

TEST(Cli, BakeFabricEstimatorAndSplitThresholdAreOptionsAndItsCountsAreReported) {
  // --estimator and --split-threshold reach the ray tracer; the splits and roulette kills are in
  // the JSON summary and the table's metadata (the same numbers); a bad or idle option is refused
  // by name before any work, with nothing written.
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "fiber.exr";
  ASSERT_EQ(
      run_weft_cli("bake fiber red-cotton --photons 2000 --resolution 3 --bands rgb --quiet -o '" +
                       fiber.string() + "'",
                   dir)
          .exit_code,
      0);
  const std::string base = "bake fabric --fiber '" + fiber.string() +
                           "' --method raytrace --detail fiber -R 2 --samples 400 --quiet --json";
  std::map<std::string, uint64_t> splits;
  for (const std::string est : {"hero", "mean", "nee"}) {
    const fs::path out = dir / (est + ".exr");
    const CliRun r = run_weft_cli(base + " --estimator " + est + " -o '" + out.string() + "'", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("estimator"), est);
    const auto t = weft::TabulatedBsdfTable::read_exr(out);
    EXPECT_EQ(t.metadata.at("estimator"), est);
    EXPECT_EQ(t.metadata.at("splits"), std::to_string(j.at("splits").get<uint64_t>()));
    EXPECT_EQ(t.metadata.at("roulette_kills"),
              std::to_string(j.at("roulette_kills").get<uint64_t>()));
    EXPECT_GT(j.at("roulette_kills").get<uint64_t>(), 0u);
    splits[est] = j.at("splits").get<uint64_t>();
    // The cost of 1 % per channel follows from this run: its CPU seconds and particles scaled by
    // (noise / 1 %)^2 (fabric_parts.h noise_cost_summary).
    const auto& cost = j.at("noise_cost");
    for (size_t c = 0; c < 3; ++c) {
      const double n = j.at("relative_noise_per_channel")[c].get<double>();
      EXPECT_NEAR(cost.at("cpu_seconds_to_target")[c].get<double>(),
                  j.at("cpu_seconds").get<double>() * n * n / 1e-4,
                  1e-9 * cost.at("cpu_seconds_to_target")[c].get<double>());
      EXPECT_EQ(cost.at("particles_per_bin_to_target")[c].get<double>(),
                std::ceil(400 * n * n / 1e-4));
    }
  }
  // Red cotton's fiber weights exceed 1 along a line near the axis: the hero estimator splits.
  EXPECT_GT(splits["hero"], 0u);
  EXPECT_EQ(splits["mean"], 0u);
  const fs::path low = dir / "low.exr";
  const CliRun r = run_weft_cli(base + " --split-threshold 0.25 -o '" + low.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("split_threshold").get<double>(), 0.25);
  EXPECT_GT(j.at("splits").get<uint64_t>(), splits["hero"]);

  const fs::path out = dir / "refused.exr";
  for (const char* bad : {"0.05", "0.01", "-1", "inf", "nan"})
    expect_refused(base + " --split-threshold " + bad, out, "--split-threshold", dir);
  expect_refused(base + " --estimator mean --split-threshold 2", out, "--split-threshold", dir);
  // The next-event estimate's counts are its own: refused with another estimator.
  expect_refused(base + " --estimator hero --next-event-rays 2", out, "--next-event-rays", dir);
  expect_refused(base + " --launch-lattice 5", out, "--launch-lattice", dir);
  // An unknown name is the option parser's refusal (its own exit code), naming the option.
  const CliRun fancy = run_weft_cli(base + " --estimator fancy -o '" + out.string() + "'", dir);
  EXPECT_NE(fancy.exit_code, 0);
  EXPECT_NE(fancy.err.find("--estimator"), std::string::npos) << fancy.err;
  EXPECT_FALSE(fs::exists(out));
  const std::string sum = "bake fabric --fiber '" + fiber.string() + "' --method summation -R 2";
  expect_refused(sum + " --estimator hero", out, "--estimator", dir);
  expect_refused(sum + " --split-threshold 2", out, "--split-threshold", dir);
  expect_refused(sum + " --max-scatterings 2", out, "--max-scatterings", dir);

  // --max-scatterings 1 ends every particle at its first fiber: the table holds the light that
  // passes straight through alone (grey: the same in every channel), what met a fiber is booked
  // as lost, and the table says it was cut.
  const fs::path cut = dir / "cut.exr";
  const CliRun c = run_weft_cli(base + " --max-scatterings 1 -o '" + cut.string() + "'", dir);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const auto jc = nlohmann::json::parse(c.out);
  EXPECT_GT(jc.at("lost").get<double>(), 0.1);
  EXPECT_GT(jc.at("scatterings").get<uint64_t>(), 0u);  // at most one per particle
  EXPECT_LE(jc.at("scatterings").get<uint64_t>(), jc.at("particles").get<uint64_t>());
  const auto tc = weft::TabulatedBsdfTable::read_exr(cut);
  EXPECT_EQ(tc.metadata.at("max_scatterings"), "1");
  for (size_t v = 0; v + 2 < tc.values.size(); v += 3) {
    ASSERT_EQ(tc.values[v], tc.values[v + 1]) << v;
    ASSERT_EQ(tc.values[v], tc.values[v + 2]) << v;
  }
  const CliRun zero = run_weft_cli(base + " --max-scatterings 0 -o '" + out.string() + "'", dir);
  EXPECT_NE(zero.exit_code, 0);  // the option parser's refusal, naming the option
  EXPECT_NE(zero.err.find("--max-scatterings"), std::string::npos) << zero.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, ExportWritesTheFormatItsExtensionNamesAndRefusesOthers) {
  // A small Lambert table; the formats' contents are checked in tests/exchange, here the command:
  // its summary, its output guard and its errors naming the option.
  const fs::path dir = fresh_test_dir();
  const fs::path table = dir / "lambert.exr";
  ASSERT_EQ(run_weft_cli(
                "table bake lambert --params '{\"reflectance\": 0.5}' -R 4 --spp 1 --quiet -o '" +
                    table.string() + "'",
                dir)
                .exit_code,
            0);
  const fs::path out = dir / "lambert.mbsdf";
  const CliRun ok =
      run_weft_cli("export --json '" + table.string() + "' -o '" + out.string() + "'", dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["format"], "MDL .mbsdf");
  EXPECT_FALSE(j["dropped"].empty());
  EXPECT_TRUE(fs::exists(out));
  for (const std::string bad : {"lambert.txt", "no-folder/lambert.bsdf"}) {
    const CliRun r =
        run_weft_cli("export '" + table.string() + "' -o '" + (dir / bad).string() + "'", dir);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("--output"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / bad));
  }
}

TEST(Cli, ViewWritesAPageForAFiberTableAndRefusesBadInputNamingTheFile) {
  // The page's contents are checked in tests/exchange (ViewPage.*); here the command: its summary,
  // and its errors naming the file with nothing written. A fiber table's page needs no three.js,
  // so this runs without scripts/install-viewer.sh.
  const fs::path dir = fresh_test_dir();
  const fs::path table = dir / "lambert.exr";
  ASSERT_EQ(run_weft_cli(
                "table bake lambert --params '{\"reflectance\": 0.5}' -R 4 --spp 1 --quiet -o '" +
                    table.string() + "'",
                dir)
                .exit_code,
            0);
  const CliRun ok = run_weft_cli(
      "view --json '" + table.string() + "' -o '" + (dir / "page.html").string() + "'", dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["format"], "HTML page of the table's in-plane curves");
  EXPECT_NE(j["notes"].dump().find("fiber table"), std::string::npos) << j.dump();
  EXPECT_NE(slurp(dir / "page.html").find("<svg id='weft-inplane'"), std::string::npos);
  write_file(dir / "notes.exr", "not a table");
  fs::create_symlink(table, dir / "link.html");
  for (const auto& [input, output, named] :
       {std::tuple{std::string("absent.exr"), std::string("a.html"), std::string("absent.exr")},
        std::tuple{std::string("notes.exr"), std::string("b.html"), std::string("notes.exr")},
        // The table itself, through a link named as a page.
        std::tuple{std::string("lambert.exr"), std::string("link.html"), std::string("table")},
        std::tuple{std::string("lambert.exr"), std::string("c.png"), std::string("--output")}}) {
    const CliRun r = run_weft_cli(
        "view '" + (dir / input).string() + "' -o '" + (dir / output).string() + "'", dir);
    EXPECT_NE(r.exit_code, 0) << input << " -> " << output;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    if (output != "link.html") EXPECT_FALSE(fs::exists(dir / output)) << output;
  }
  EXPECT_EQ(weft::TabulatedBsdfTable::read_exr(table).resolution, 4) << "the table was overwritten";
}

TEST(Cli, ExportPrintsHowTransmissionIsCarried) {
  // A red cloth transmitting a red of its own, Lambertian both ways (rho, tau per channel): the
  // glTF gets the diffuse transmission with the fit's error, the .mbsdf both directions at their
  // mean (here equal, so no error).
  const fs::path dir = fresh_test_dir();
  const fs::path table = dir / "red.exr";
  const std::vector<double> rho{0.5, 0.1, 0.05}, tau{0.4, 0.08, 0.04};
  weft::TabulatedBsdfTable::from_function(
      4, 3,
      [&](const weft::Vec3& wo, const weft::Vec3& wi, std::span<double> v) {
        for (size_t c = 0; c < 3; ++c) v[c] = ((wo.z > 0) == (wi.z > 0) ? rho : tau)[c] / weft::kPi;
      },
      1, 1)
      .write_exr(table);
  const CliRun glb = run_weft_cli(
      "export --json '" + table.string() + "' -o '" + (dir / "red.glb").string() + "'", dir);
  ASSERT_EQ(glb.exit_code, 0) << glb.err;
  const auto g = nlohmann::json::parse(glb.out);
  EXPECT_GT(g["figures"]["diffuse transmission"].get<double>(), 0);
  // The colour keeps the table's red: tau's channel ratios, within the fit's largest error.
  const double err = g["figures"]["transmission fit max relative error"];
  const double r = g["figures"]["diffuse transmission color R"],
               gg = g["figures"]["diffuse transmission color G"];
  EXPECT_NEAR(gg / r, tau[1] / tau[0], 2 * err * tau[1] / tau[0] + 1e-9);
  EXPECT_EQ(g["figures"]["transmission"], 0.0);  // no KHR_materials_transmission
  const std::string notes = g["notes"].dump();
  EXPECT_NE(notes.find("KHR_materials_diffuse_transmission"), std::string::npos) << notes;
  const CliRun mdl = run_weft_cli(
      "export --json '" + table.string() + "' -o '" + (dir / "red.mbsdf").string() + "'", dir);
  ASSERT_EQ(mdl.exit_code, 0) << mdl.err;
  const auto m = nlohmann::json::parse(mdl.out);
  EXPECT_LT(m["figures"]["transmission direction error (max relative)"].get<double>(), 1e-5);
  EXPECT_NEAR(m["figures"]["transmittance either way (file)"].get<double>(),
              (0.4 + 0.08 + 0.04) / 3, 1e-3);
}

TEST(Cli, BakeFabricBooksTheSheenApartWhereItCan) {
  // --sheen-resolution reaches the ray trace at fiber detail from a fiber table with an analytic
  // surface lobe: the table holds the sheen. Where it cannot be booked (yarn detail, parts) or
  // its window is bad, it is refused by name before any work, with nothing written.
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "filament.exr";
  const CliRun f = run_weft_cli(
      "bake fiber polyester-filament --bands rgb --surface-lobe analytic "
      "--resolution 2 --photons 400 --quiet -o '" +
          fiber.string() + "'",
      dir);
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const std::string base = "bake fabric --fiber '" + fiber.string() +
                           "' --method raytrace -R 2 --samples 20 --weave '" + WEFT_SOURCE_DIR +
                           "/scenes/examples/polyester-satin-weave.json'";
  const fs::path out = dir / "refused.exr";
  expect_refused(base + " --detail yarn --sheen-resolution 16", out, "--sheen-resolution", dir);
  // The sample file's own detail (fiber) holds where --detail is not given.
  const std::string fiber_detail = base;
  expect_refused(fiber_detail + " --sheen-window 4", out, "--sheen-window", dir);
  expect_refused(fiber_detail + " --sheen-resolution 300", out, "--sheen-resolution", dir);
  expect_refused(fiber_detail + " --sheen-resolution 15", out, "--sheen-window", dir);
  expect_refused(fiber_detail + " --sheen-resolution 16 --sheen-window 18", out, "--sheen-window",
                 dir);
  expect_refused(fiber_detail + " --sheen-resolution 16 --shard 1/2", out, "--sheen-resolution",
                 dir);
  expect_refused(fiber_detail + " --sheen-light-resolution 4", out, "--sheen-light-resolution",
                 dir);
  expect_refused(fiber_detail + " --sheen-resolution 16 --sheen-light-resolution 3", out,
                 "--sheen-light-resolution", dir);
  expect_refused(fiber_detail + " --sheen-light reflected", out, "--sheen-light", dir);
  expect_refused(fiber_detail + " --sheen-resolution 16 --sheen-light mirror", out, "--sheen-light",
                 dir);
  const fs::path sheen = dir / "sheen.exr";
  const CliRun r =
      run_weft_cli(fiber_detail +
                       " --sheen-resolution 16 --sheen-window 4 "
                       "--sheen-light-resolution 4 --sheen-light reflected --json -o '" +
                       sheen.string() + "'",
                   dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto t = weft::TabulatedBsdfTable::read_exr(sheen);
  ASSERT_TRUE(t.sheen);
  EXPECT_EQ(t.sheen->h_resolution, 16);
  EXPECT_EQ(t.sheen->window, 4);
  EXPECT_EQ(t.sheen->light_resolution, 4);
  EXPECT_EQ(t.metadata.at("sheen_light"), "reflected");
}
