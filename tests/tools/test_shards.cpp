// Long jobs split and survived: shards merged by `weft merge` give the bytes of the one-process
// run (bake fiber, bake fabric --method raytrace, sweep); merge refuses parts of other jobs,
// duplicates and missing shards (naming them); runs killed with SIGKILL at random moments and
// resumed with --resume end with the bytes of an uninterrupted run; outputs never overwrite
// inputs or each other.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;
using weft::testing::fresh_test_dir;

namespace {

using weft::testing::slurp;

std::vector<std::string> split(const std::string& args) {
  std::vector<std::string> out;
  std::istringstream in(args);
  std::string a;
  while (in >> a) out.push_back(a);
  return out;
}

// Starts weft with 'args' (no shell; stdout and stderr to files in 'dir').
pid_t spawn(const std::vector<std::string>& args, const fs::path& dir) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string out = (dir / "stdout").string(), err = (dir / "stderr").string();
    if (!std::freopen(out.c_str(), "w", stdout) || !std::freopen(err.c_str(), "w", stderr))
      _exit(126);
    std::vector<char*> argv;
    std::string exe = WEFT_EXE;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(WEFT_EXE, argv.data());
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int run_weft(const std::vector<std::string>& args, const fs::path& dir) {
  return wait_exit(spawn(args, dir));
}

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Runs 'args' as 4 shards, merges them (with 'merge_options') and expects the bytes of
// 'reference'; what the merge printed goes to 'printed' when given.
void expect_shards_merge_to(const std::vector<std::string>& args, const fs::path& reference,
                            const fs::path& dir, const std::string& ext,
                            const std::vector<std::string>& merge_options = {},
                            std::string* printed = nullptr) {
  std::vector<std::string> merge = {"merge"};
  for (int k = 0; k < 4; ++k) {
    const fs::path part = dir / ("part-" + std::to_string(k) + ".part");
    ASSERT_EQ(run_weft(args + std::vector<std::string>{"--shard", std::to_string(k) + "/4", "-o",
                                                       part.string()},
                       dir),
              0)
        << slurp(dir / "stderr");
    merge.push_back(part.string());
  }
  // Any order of the parts.
  std::swap(merge[1], merge[3]);
  const fs::path merged = dir / ("merged" + ext);
  ASSERT_EQ(run_weft(merge + merge_options + std::vector<std::string>{"-o", merged.string()}, dir),
            0)
      << slurp(dir / "stderr");
  if (printed) *printed = slurp(dir / "stdout");
  const std::string a = slurp(reference), b = slurp(merged);
  EXPECT_GT(a.size(), 0u);
  EXPECT_TRUE(a == b) << reference << " and " << merged << " differ";
}

const std::vector<std::string> kFiberBake =
    split("bake fiber red-cotton --photons 3000 --resolution 3 --passes 4 --quiet --threads 2");
const std::string kScene = std::string(WEFT_SOURCE_DIR) + "/scenes/examples/woven-patch.json";
const std::vector<std::string> kSweep =
    split("sweep " + kScene + " --spp 2 --resolution 12 --quiet --threads 2");

}  // namespace

TEST(Shards, FiberBakeOfFourShardsMergesToTheOneProcessBytes) {
  const fs::path dir = fresh_test_dir();
  for (const char* bands : {"spectral", "rgb"}) {
    const auto args = kFiberBake + std::vector<std::string>{"--bands", bands};
    const fs::path one = dir / (std::string("one-") + bands + ".exr");
    ASSERT_EQ(run_weft(args + std::vector<std::string>{"-o", one.string()}, dir), 0)
        << slurp(dir / "stderr");
    expect_shards_merge_to(args, one, dir, ".exr");
  }
}

TEST(Shards, RaytracedFabricOfFourShardsMergesToTheOneProcessBytes) {
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "fiber.exr";
  ASSERT_EQ(
      run_weft(kFiberBake + std::vector<std::string>{"--bands", "rgb", "-o", fiber.string()}, dir),
      0);
  // 2100 particles per bin: the batch runner's tasks of 2048 straddle incident bins, so a
  // shard's first and last task hold particles of its neighbours' bins (and with the nee
  // estimator, launch blocks of 13 straddle tasks).
  for (const std::string estimator : {"hero", "nee"}) {
    const auto args =
        split("bake fabric --method raytrace -R 2 --samples 2100 --quiet --estimator " + estimator +
              " --fiber " + fiber.string());
    const fs::path one = dir / ("one-" + estimator + ".exr");
    ASSERT_EQ(run_weft(args + std::vector<std::string>{"--json", "-o", one.string()}, dir), 0)
        << slurp(dir / "stderr");
    const auto whole = nlohmann::json::parse(slurp(dir / "stdout"));
    std::string printed;
    expect_shards_merge_to(args, one, dir, ".exr", {"--json"}, &printed);
    ASSERT_FALSE(printed.empty());
    const auto merged = nlohmann::json::parse(printed);
    // The energy books, counts and noise are sums over the bins in bin order: the merge has the
    // whole run's bits (JSON numbers print with round-trip precision).
    for (const char* key : {"exited", "absorbed", "lost", "roulette_net", "relative_noise",
                            "relative_noise_per_channel", "particles", "scatterings",
                            "reflectance_normal_incidence", "transmittance_normal_incidence"}) {
      ASSERT_TRUE(whole.contains(key) && merged.contains(key)) << key;
      EXPECT_FALSE(merged[key].is_null()) << key;
      EXPECT_EQ(whole[key].dump(), merged[key].dump()) << key;
    }
    EXPECT_GT(merged["relative_noise"].get<double>(), 0.0);
    EXPECT_NEAR(merged["exited"].get<double>() + merged["absorbed"].get<double>() +
                    merged["lost"].get<double>() + merged["roulette_net"].get<double>(),
                1.0, 1e-9);  // fabric_raytrace.h: the books add up to 1 to rounding
  }
}

TEST(Shards, RaytracedFabricWithPerYarnFibersMergesToTheOneProcessBytes) {
  // Warp and weft on fiber tables of their own (bake fabric --warp-fiber / --weft-fiber): the
  // shards of that trace merge to its one-process bytes too.
  const fs::path dir = fresh_test_dir();
  const fs::path red = dir / "red.exr", white = dir / "white.exr";
  ASSERT_EQ(
      run_weft(kFiberBake + std::vector<std::string>{"--bands", "rgb", "-o", red.string()}, dir),
      0);
  auto white_bake = kFiberBake;
  white_bake[2] = "white-cotton";
  ASSERT_EQ(
      run_weft(white_bake + std::vector<std::string>{"--bands", "rgb", "-o", white.string()}, dir),
      0);
  const auto args = split("bake fabric --method raytrace -R 2 --samples 500 --quiet --warp-fiber " +
                          red.string() + " --weft-fiber " + white.string());
  const fs::path one = dir / "one.exr";
  ASSERT_EQ(run_weft(args + std::vector<std::string>{"-o", one.string()}, dir), 0)
      << slurp(dir / "stderr");
  expect_shards_merge_to(args, one, dir, ".exr");
}

TEST(Shards, SweepOfFourShardsMergesToTheOneProcessBytes) {
  const fs::path dir = fresh_test_dir();
  // The scene normalizes (to beta at normal incidence): the reference render is a unit too.
  for (const char* light : {"30", "0"}) {
    const auto args = kSweep + std::vector<std::string>{"--light-zenith-deg", light};
    const fs::path one = dir / (std::string("one-") + light + ".csv");
    ASSERT_EQ(run_weft(args + std::vector<std::string>{"-o", one.string()}, dir), 0)
        << slurp(dir / "stderr");
    expect_shards_merge_to(args, one, dir, ".csv");
  }
}

TEST(Shards, MergeRefusesMissingDuplicateAndForeignParts) {
  const fs::path dir = fresh_test_dir();
  auto part = [&](const std::string& name, const std::string& shard, const std::string& seed) {
    const fs::path p = dir / name;
    EXPECT_EQ(
        run_weft(split("bake fiber red-cotton --photons 200 --resolution 2 --passes 1 --quiet "
                       "--seed " +
                       seed + " --shard " + shard + " -o " + p.string()),
                 dir),
        0);
    return p.string();
  };
  const std::string p0 = part("p0", "0/3", "1"), p1 = part("p1", "1/3", "1"),
                    p2 = part("p2", "2/3", "1"), other = part("other", "2/3", "2");
  const fs::path out = dir / "out.exr";
  auto refused = [&](const std::vector<std::string>& parts, const std::string& says) {
    EXPECT_EQ(run_weft(std::vector<std::string>{"merge"} + parts +
                           std::vector<std::string>{"-o", out.string()},
                       dir),
              2);
    const std::string err = slurp(dir / "stderr");
    EXPECT_NE(err.find(says), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
  };
  refused({p0, p2}, "missing shard 1/3");
  refused({p0, p1, p1, p2}, "given twice");
  refused({p0, p1, other}, "belongs to another job");
  refused({p0, p1, p2, dir / "stdout"}, "not a weft part");
  // A truncated part is named, not read past its end.
  const std::string bytes = slurp(p2);
  std::ofstream(dir / "cut", std::ios::binary) << bytes.substr(0, bytes.size() - 8);
  refused({p0, p1, (dir / "cut").string()}, "truncated");
  EXPECT_EQ(run_weft({"merge", p2, p0, p1, "-o", out.string()}, dir), 0) << slurp(dir / "stderr");
}

// A part whose header's job or extra is edited (a corrupt or crafted part): each setting is read
// through the checks a job file gets, so a merge refuses it naming the setting, with exit 2 and
// no output, instead of casting 1e30 to an int or sizing a table by a crafted count.
TEST(Shards, MergeRefusesPartsWithCraftedSettings) {
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "fiber.exr";
  ASSERT_EQ(run_weft(split("bake fiber red-cotton --photons 200 --resolution 2 --passes 1 "
                           "--quiet --bands rgb -o " +
                           fiber.string()),
                     dir),
            0)
      << slurp(dir / "stderr");
  // Two shards of each job (a whole run writes its output, not a part).
  auto shards = [&](const std::string& args, const std::string& name) {
    std::vector<fs::path> parts;
    for (const char* k : {"0/2", "1/2"}) {
      parts.push_back(dir / (name + std::to_string(parts.size())));
      EXPECT_EQ(run_weft(split(args + " --shard " + k + " -o " + parts.back().string()), dir), 0)
          << slurp(dir / "stderr");
    }
    return parts;
  };
  const auto fiber_parts = shards(
      "bake fiber red-cotton --photons 200 --resolution 2 --passes 1 --quiet --bands rgb", "f");
  const auto fabric_parts = shards(
      "bake fabric --method raytrace -R 2 --samples 64 --quiet --fiber " + fiber.string(), "r");
  // The parts with one header value replaced in each: the magic line, the edited header, the
  // payload.
  auto edited = [&](const std::vector<fs::path>& parts, const std::string& object,
                    const std::string& key, const nlohmann::json& value) {
    std::vector<std::string> out = {"merge"};
    for (const fs::path& part : parts) {
      const std::string bytes = slurp(part);
      const size_t first = bytes.find('\n'), second = bytes.find('\n', first + 1);
      nlohmann::json h = nlohmann::json::parse(bytes.substr(first + 1, second - first - 1));
      h[object][key] = value;
      out.push_back((dir / ("crafted-" + part.filename().string())).string());
      std::ofstream(out.back(), std::ios::binary)
          << bytes.substr(0, first + 1) << h.dump() << bytes.substr(second);
    }
    return out;
  };
  const fs::path out = dir / "out.exr";
  const std::vector<std::string> to_out = {"-o", out.string()};
  struct Case {
    const std::vector<fs::path>& parts;
    std::string object, key;
    nlohmann::json value;
    std::string says;
  };
  const std::vector<Case> cases = {
      {fiber_parts, "job", "resolution", 1e30, "job.resolution"},
      {fiber_parts, "job", "seed", -1, "job.seed"},
      {fiber_parts, "job", "photons_per_band", 0.5, "job.photons_per_band"},
      {fiber_parts, "job", "surface_samples", 1e9, "job.surface_samples"},
      {fiber_parts, "job", "route", "sideways", "job.route"},
      {fabric_parts, "job", "resolution", 3, "units_total"},
      {fabric_parts, "job", "resolution", 1e30, "job.resolution"},
      {fabric_parts, "extra", "channels", 1e30, "extra.channels"},
      {fabric_parts, "extra", "channels", 4, "channels"},
      {fabric_parts, "extra", "metadata", {{"spec", 1}}, "extra.metadata.spec"},
      {fabric_parts, "job", "sample", 7, "job.sample"}};
  for (const Case& c : cases) {
    EXPECT_EQ(run_weft(edited(c.parts, c.object, c.key, c.value) + to_out, dir), 2)
        << c.key << " = " << c.value.dump() << ": " << slurp(dir / "stderr");
    const std::string err = slurp(dir / "stderr");
    EXPECT_NE(err.find(c.says), std::string::npos) << c.key << ": " << err;
    EXPECT_FALSE(fs::exists(out));
  }
  // Parts edited to what they held merge.
  EXPECT_EQ(run_weft(edited(fabric_parts, "extra", "channels", 3) + to_out, dir), 0)
      << slurp(dir / "stderr");
}

// SIGKILL at random moments (seeded: the same moments every run), each run continuing from the
// checkpoint the killed one left, then a last run to the end: the bytes of an uninterrupted run.
// Delays are uniform over [0, 1.2 x] the uninterrupted run's time, however loaded the machine.
void kill_and_resume(const std::vector<std::string>& args, const std::string& ext, int trials,
                     const fs::path& dir = fresh_test_dir()) {
  const fs::path one = dir / ("one" + ext);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run_weft(args + std::vector<std::string>{"-o", one.string()}, dir), 0)
      << slurp(dir / "stderr");
  const int max_delay_ms = static_cast<int>(
      1.2 *
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  std::mt19937 rng(20261201);
  int killed = 0, finished_first = 0, from_checkpoint = 0;
  for (int t = 0; t < trials; ++t) {
    const fs::path out = dir / ("resumed-" + std::to_string(t) + ext);
    const auto run = args + std::vector<std::string>{"--resume", "-o", out.string()};
    const fs::path checkpoint = dir / ("." + out.filename().string() + ".weft-checkpoint");
    for (int k = 0; k < 3; ++k) {
      if (fs::exists(checkpoint)) ++from_checkpoint;
      const pid_t pid = spawn(run, dir);
      int status = 0;
      bool reaped = false;
      // The second kill of a trial waits for a checkpoint first, so that some runs continue
      // from one however fast or loaded the machine; the others die at any moment.
      if (k == 1)
        while (!fs::exists(checkpoint) && !(reaped = waitpid(pid, &status, WNOHANG) == pid))
          std::this_thread::sleep_for(std::chrono::milliseconds(2));
      std::this_thread::sleep_for(std::chrono::milliseconds(
          std::uniform_int_distribution<int>(0, k == 1 ? max_delay_ms / 4 : max_delay_ms)(rng)));
      kill(pid, SIGKILL);
      if (!reaped) waitpid(pid, &status, 0);
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      if (code == 128 + SIGKILL) ++killed;
      if (code == 0) ++finished_first;
      EXPECT_TRUE(code == 0 || code == 128 + SIGKILL) << code << ": " << slurp(dir / "stderr");
    }
    if (fs::exists(checkpoint)) ++from_checkpoint;
    ASSERT_EQ(run_weft(run, dir), 0) << slurp(dir / "stderr");
    EXPECT_TRUE(slurp(one) == slurp(out)) << "trial " << t << ": " << out << " differs";
    EXPECT_FALSE(fs::exists(checkpoint));
  }
  std::printf(
      "kill/resume: %d trials, %d runs killed, %d finished before their kill, %d runs started "
      "from a checkpoint\n",
      trials, killed, finished_first, from_checkpoint);
  EXPECT_GT(from_checkpoint, 0);  // resuming was exercised, not only starting afresh
}

TEST(Resume, FiberBakeKilledAtRandomMomentsResumesToTheSameBytes) {
  kill_and_resume(split("bake fiber red-cotton --photons 6000 --resolution 3 --passes 12 "
                        "--quiet --threads 2"),
                  ".exr", 6);
}

TEST(Resume, SweepKilledAtRandomMomentsResumesToTheSameBytes) {
  // Views heavy enough that a run's time is mostly rendering, not loading the scene.
  kill_and_resume(split("sweep " + kScene +
                        " --spp 16 --resolution 24 --quiet --threads 2 --light-zenith-deg 0"),
                  ".csv", 6);
}

TEST(Resume, ShardOfARaytracedFabricKilledAtRandomMomentsResumesToTheSameBytes) {
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "fiber.exr";
  ASSERT_EQ(
      run_weft(kFiberBake + std::vector<std::string>{"--bands", "rgb", "-o", fiber.string()}, dir),
      0);
  kill_and_resume(split("bake fabric --method raytrace -R 3 --samples 3000 --quiet --shard 1/2 "
                        "--threads 2 --fiber " +
                        fiber.string()),
                  ".part", 4, dir);
}

TEST(Shards, WeaveTallyTravelsInThePartsAndMergesToTheOneProcessBytes) {
  // bake fabric --weave-out: the parts carry each bin's weave books, and `weft merge --weave-out`
  // writes the weave table of the one-process run, bit for bit (2100 particles per bin: tasks
  // straddle bins, as above).
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = dir / "fiber.exr";
  ASSERT_EQ(
      run_weft(kFiberBake + std::vector<std::string>{"--bands", "rgb", "-o", fiber.string()}, dir),
      0);
  const auto args = split(
      "bake fabric --method raytrace -R 2 --samples 2100 --quiet "
      "--weave-positions 3x2 --weave-resolution 1 --fiber " +
      fiber.string());
  const fs::path one = dir / "one.exr", one_weave = dir / "one-weave.exr";
  ASSERT_EQ(run_weft(args + std::vector<std::string>{"--json", "-o", one.string(), "--weave-out",
                                                     one_weave.string()},
                     dir),
            0)
      << slurp(dir / "stderr");
  const auto whole = nlohmann::json::parse(slurp(dir / "stdout"));
  ASSERT_TRUE(whole.contains("weave"));
  EXPECT_EQ(whole["weave"]["positions"], "3x2");
  EXPECT_EQ(whole["weave"]["resolution"], 1);
  EXPECT_GT(whole["weave"]["relative_noise"].get<double>(), 0.0);
  const fs::path merged_weave = dir / "merged-weave.exr";
  std::string printed;
  expect_shards_merge_to(
      args + std::vector<std::string>{"--weave-out", (dir / "unused.exr").string()}, one, dir,
      ".exr", {"--json", "--weave-out", merged_weave.string()}, &printed);
  EXPECT_FALSE(fs::exists(dir / "unused.exr"));  // a shard writes its part only
  const std::string a = slurp(one_weave), b = slurp(merged_weave);
  EXPECT_GT(a.size(), 0u);
  EXPECT_TRUE(a == b) << "the merged weave table differs from the one-process run's";
  EXPECT_EQ(nlohmann::json::parse(printed)["weave"]["relative_noise"].dump(),
            whole["weave"]["relative_noise"].dump());
  // The parts carry a weave: a merge without --weave-out is refused by name.
  std::vector<std::string> merge = {"merge"};
  for (int k = 0; k < 4; ++k)
    merge.push_back((dir / ("part-" + std::to_string(k) + ".part")).string());
  EXPECT_EQ(run_weft(merge + std::vector<std::string>{"-o", (dir / "m2.exr").string()}, dir), 2);
  EXPECT_NE(slurp(dir / "stderr").find("--weave-out"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "m2.exr"));
  // --resume (checkpoints of the whole run) writes the same weave table.
  const fs::path resumed_weave = dir / "resumed-weave.exr";
  ASSERT_EQ(run_weft(args + std::vector<std::string>{"--resume", "-o", (dir / "r.exr").string(),
                                                     "--weave-out", resumed_weave.string()},
                     dir),
            0)
      << slurp(dir / "stderr");
  EXPECT_TRUE(slurp(resumed_weave) == a);
  EXPECT_TRUE(slurp(dir / "r.exr") == slurp(one));
  // weft slurm's merge job writes the weave table the wrapped command names.
  const fs::path slurm_weave = dir / "sw.exr";
  ASSERT_EQ(run_weft(split("slurm --shards 2 --dry-run bake fabric --method raytrace -R 2 "
                           "--samples 100 -o " +
                           (dir / "s.exr").string() + " --weave-out " + slurm_weave.string()),
                     dir),
            0)
      << slurp(dir / "stderr");
  const std::string scripts = slurp(dir / "stdout");
  ASSERT_NE(scripts.find(" merge "), std::string::npos) << scripts;
  const std::string merge_line = scripts.substr(scripts.find(" merge "));
  EXPECT_NE(merge_line.find("--weave-out '" + slurm_weave.string() + "'"), std::string::npos)
      << scripts;
}

namespace {

// RFC 4648 base64 (the bundled glTF's data URI) to bytes.
std::string from_base64(const std::string& text) {
  const std::string abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    const auto v = abc.find(c);
    if (v == std::string::npos) break;  // '=' padding
    acc = (acc << 6) | static_cast<uint32_t>(v);
    if ((bits += 6) >= 8) out.push_back(static_cast<char>((acc >> (bits -= 8)) & 0xff));
  }
  return out;
}

// The bundled Lambert plane with its buffer in an external plane.bin, in 'dir'; returns the
// scene description's path.
fs::path plane_with_external_buffer(const fs::path& dir) {
  const fs::path examples = fs::path(WEFT_SOURCE_DIR) / "scenes/examples";
  auto gltf = nlohmann::json::parse(slurp(examples / "lambert-plane.gltf"));
  const std::string uri = gltf["buffers"][0]["uri"];
  std::ofstream(dir / "plane.bin", std::ios::binary) << from_base64(uri.substr(uri.find(',') + 1));
  gltf["buffers"][0]["uri"] = "plane.bin";
  std::ofstream(dir / "lambert-plane.gltf") << gltf.dump(1);
  fs::copy_file(examples / "lambert-plane.json", dir / "plane.json");
  return dir / "plane.json";
}

}  // namespace

// A sweep's identity holds the content of the files its scene reads: a glTF buffer changed between
// two shards makes merge refuse, naming the file; a glTF changed after a killed run makes --resume
// refuse its checkpoint, naming the file, instead of mixing views of two scenes.
TEST(Shards, ChangedGltfOrBufferInvalidatesPartsAndCheckpoints) {
  const fs::path dir = fresh_test_dir();
  const std::string scene = plane_with_external_buffer(dir).string();
  const auto sweep = split("sweep " + scene + " --quiet --threads 2");
  const std::string p0 = (dir / "p0.part").string(), p1 = (dir / "p1.part").string();
  ASSERT_EQ(run_weft(sweep + split("--shard 0/2 -o " + p0), dir), 0) << slurp(dir / "stderr");
  // Texture coordinates (bytes 160..191, unused in shading, but content all the same).
  std::string bin = slurp(dir / "plane.bin");
  bin[170] = static_cast<char>(bin[170] ^ 1);
  std::ofstream(dir / "plane.bin", std::ios::binary) << bin;
  ASSERT_EQ(run_weft(sweep + split("--shard 1/2 -o " + p1), dir), 0) << slurp(dir / "stderr");
  const fs::path merged = dir / "merged.csv";
  EXPECT_EQ(run_weft({"merge", p0, p1, "-o", merged.string()}, dir), 2);
  std::string err = slurp(dir / "stderr");
  EXPECT_NE(err.find("another job"), std::string::npos) << err;
  EXPECT_NE(err.find("content of " + (dir / "plane.bin").string()), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(merged));

  // A run killed after its first checkpoint (heavy views: it lasts well beyond that).
  const fs::path out = dir / "resumed.csv", checkpoint = dir / ".resumed.csv.weft-checkpoint";
  const auto run = sweep + split("--spp 256 --resolution 64 --resume -o " + out.string());
  const pid_t pid = spawn(run, dir);
  int status = 0;
  bool reaped = false;
  while (!fs::exists(checkpoint) && !(reaped = waitpid(pid, &status, WNOHANG) == pid))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_FALSE(reaped) << "the sweep ended before its first checkpoint";
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  ASSERT_TRUE(fs::exists(checkpoint));
  std::string gltf = slurp(dir / "lambert-plane.gltf");
  gltf.insert(gltf.find("\"version\""), "\"copyright\": \"changed\", ");
  std::ofstream(dir / "lambert-plane.gltf") << gltf;
  EXPECT_EQ(run_weft(run, dir), 2);
  err = slurp(dir / "stderr");
  EXPECT_NE(err.find("checkpoint of another job"), std::string::npos) << err;
  EXPECT_NE(err.find("content of " + (dir / "lambert-plane.gltf").string()), std::string::npos)
      << err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Outputs, NeverOverwriteInputsOrEachOther) {
  const fs::path dir = fresh_test_dir();
  const fs::path scene = dir / "s.json", spec = dir / "spec.json";
  fs::copy_file(kScene, scene);
  fs::copy_file(fs::path(kScene).parent_path() / "woven-patch.gltf", dir / "woven-patch.gltf");
  std::ofstream(spec) << R"({"name": "t", "fiber_radius_um": 6,
    "roughness": {"distribution": "beckmann", "alpha": 0.3}, "host": {"n": 1.557},
    "species": []})";
  const std::string scene_bytes = slurp(scene), spec_bytes = slurp(spec);
  auto refused = [&](const std::string& args) {
    EXPECT_EQ(run_weft(split(args), dir), 2) << args;
    EXPECT_NE(slurp(dir / "stderr").find("refusing to overwrite"), std::string::npos)
        << slurp(dir / "stderr");
  };
  refused("sweep " + scene.string() + " --spp 1 --resolution 4 -o " + scene.string());
  // The same file by another spelling.
  refused("sweep " + scene.string() + " --spp 1 --resolution 4 -o " +
          (dir / "." / "s.json").string());
  refused("bake fiber " + spec.string() + " --photons 10 --resolution 2 -o " + spec.string());
  const fs::path x = dir / "x.exr";
  refused("render " + scene.string() + " --spp 1 --width 4 --height 4 -o " + x.string() +
          " --mask " + x.string() + " --mask-object patch");
  EXPECT_FALSE(fs::exists(x));
  EXPECT_EQ(slurp(scene), scene_bytes);
  EXPECT_EQ(slurp(spec), spec_bytes);
}
