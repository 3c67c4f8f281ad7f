// Ctrl-C and the estimates, from outside the process: a SIGINT ends a long run within a bounded
// time whatever the size of its work, and a run's peak memory is within its estimate's reach.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_run.h"
#include "test_util.h"
#include "weft/integrators/path_tracer.h"
#include "weft/integrators/render_settings.h"
#include "weft/materials/bsdf_table.h"

namespace fs = std::filesystem;
using namespace weft::testing;

namespace {

struct ChildRun {
  pid_t pid = -1;
};

// weft ARGS in 'dir' (stdout and stderr in files there), SIGINT at its default action: unlike a
// background job of sh, which starts with it ignored.
ChildRun spawn_weft(const std::vector<std::string>& args, const fs::path& dir) {
  ChildRun c;
  c.pid = fork();
  if (c.pid == 0) {
    std::signal(SIGINT, SIG_DFL);
    if (chdir(dir.c_str()) != 0) _exit(126);
    if (!freopen("stdout", "w", stdout) || !freopen("stderr", "w", stderr)) _exit(126);
    std::vector<char*> argv{const_cast<char*>(WEFT_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(WEFT_EXE, argv.data());
    _exit(127);
  }
  return c;
}

// Whether the process has its SIGINT handler (SigCgt bit 1): the work starts once it does.
bool catches_sigint(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string key, value;
  while (in >> key >> value)
    if (key == "SigCgt:") return (std::stoull(value, nullptr, 16) & 2) != 0;
  return false;
}

struct Interrupted {
  int status = 0;
  double seconds_to_exit = -1;
};

// Waits for the handler and for 'ready' when given (at most 'wait_s' in all), lets the command
// run 'run_s', sends SIGINT and times the exit.
Interrupted interrupt_after(ChildRun c, double run_s, double wait_s = 120,
                            const std::function<bool()>& ready = nullptr, int signal = SIGINT) {
  using Clock = std::chrono::steady_clock;
  const auto give_up = Clock::now() + std::chrono::duration<double>(wait_s);
  while (!(catches_sigint(c.pid) && (!ready || ready())) && Clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::duration<double>(run_s));
  const auto t0 = Clock::now();
  kill(c.pid, signal);
  Interrupted r;
  waitpid(c.pid, &r.status, 0);
  r.seconds_to_exit = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

// The exit within 2 s of the signal; the 1 s margin is for this test's machines, 2 cores shared
// by several builds (docs/ARCHITECTURE.md, "Ctrl-C").
constexpr double kExitWithinSeconds = 2 + 1;

// What weft says when Ctrl-C comes before its work polls (tools/cli_util.cpp).
constexpr const char* kInterruptedBeforeWork = "\nweft: interrupted\n";

void expect_nothing_written(const Interrupted& r, const fs::path& dir, const fs::path& out) {
  ASSERT_TRUE(WIFEXITED(r.status)) << "ended by signal " << WTERMSIG(r.status);
  EXPECT_NE(WEXITSTATUS(r.status), 0);
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// Stopped by the work's own poll (not before the work began), soon, with nothing written.
void expect_cancelled(const Interrupted& r, const fs::path& dir, const fs::path& out) {
  const std::string err = slurp(dir / "stderr");
  EXPECT_LT(r.seconds_to_exit, kExitWithinSeconds) << err;
  EXPECT_EQ(err.find(kInterruptedBeforeWork), std::string::npos) << err;
  expect_nothing_written(r, dir, out);
}

// expect_cancelled, and the command's own stop: exit 130 and "WHAT cancelled" on stderr.
void expect_stopped(const Interrupted& r, const fs::path& dir, const fs::path& out,
                    const std::string& what) {
  expect_cancelled(r, dir, out);
  EXPECT_EQ(WEXITSTATUS(r.status), 130);
  EXPECT_NE(slurp(dir / "stderr").find(what + " cancelled"), std::string::npos)
      << slurp(dir / "stderr");
}

// A fiber table of little albedo, so that the fabric bake starts its ray trace at once.
fs::path flat_fiber_table(const fs::path& dir) {
  auto t = weft::TabulatedBsdfTable::from_function(
      4, 3,
      [](const weft::Vec3&, const weft::Vec3&, std::span<double> v) { v[0] = v[1] = v[2] = 0.05; },
      1, 1);
  t.kind = "fiber";
  t.write_exr(dir / "fiber.exr");
  return dir / "fiber.exr";
}

TEST(CliCancel, FabricRaytraceStopsSoonAtHugeSamples) {
  // 2^30 particles per bin: one bin's straight-through rays alone once ran for minutes unpolled.
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = flat_fiber_table(dir);
  const auto r = interrupt_after(
      spawn_weft({"bake", "fabric", "--method", "raytrace", "--fiber", fiber.string(), "-R", "4",
                  "--samples", "1073741824", "--yes-long", "--quiet", "-o", "fabric.exr"},
                 dir),
      1.0);
  expect_cancelled(r, dir, dir / "fabric.exr");
}

TEST(CliCancel, FabricRaytraceStopsSoonWhileMakingALargeSample) {
  // The bundled 84 x 100 draft at fiber detail: its sample (4 M segments) took 100-160 s to make
  // on the shared 2-core machine, and its scene build tens of seconds more, neither polled;
  // interrupted 2 s in, the stop is the sample's own poll (the plan is done well before).
  // 4 s in is the fiber-distance check after the yarns (2026-12-06: its gathering and sorting of
  // the 4 M segments were unpolled, and the stop came 6-8 s later).
  for (const double seconds : {2.0, 4.0}) {
    const fs::path dir = fresh_test_dir();
    const fs::path fiber = flat_fiber_table(dir);
    const std::string draft = std::string(WEFT_SOURCE_DIR) + "/scenes/data/wif/8452.wif";
    const auto r = interrupt_after(
        spawn_weft({"--max-memory-gb", "64", "bake", "fabric", "--method", "raytrace", "--detail",
                    "fiber", "--wif", draft, "--fiber", fiber.string(), "-R", "1", "--yes-long",
                    "--quiet", "-o", "fabric.exr"},
                   dir),
        seconds);
    SCOPED_TRACE(seconds);
    expect_stopped(r, dir, dir / "fabric.exr", "bake");
  }
}

TEST(CliCancel, FabricRaytraceStopsSoonWhileMakingALargeYarnSample) {
  // Plain weave tiled 110 x 110 at yarn detail: 4.96e7 triangles, just under the limit of 5e7
  // (weave.cpp). Making its tubes took 17 s on the shared 2-core machine, unpolled: Ctrl-C 2 s in
  // once ended the run 36 s later (2026-12-05). Now the tubes poll every 64 k vertices.
  const fs::path dir = fresh_test_dir();
  const fs::path fiber = flat_fiber_table(dir);
  std::ofstream(dir / "weave.json") << R"({"pattern": "plain", "repeats": [110, 110]})";
  const auto r = interrupt_after(
      spawn_weft({"--max-memory-gb", "64", "bake", "fabric", "--method", "raytrace", "--detail",
                  "yarn", "--weave", "weave.json", "--fiber", fiber.string(), "-R", "1",
                  "--yes-long", "--quiet", "-o", "fabric.exr"},
                 dir),
      2.0);
  expect_stopped(r, dir, dir / "fabric.exr", "bake");
}

TEST(CliCancel, VerifyStopsSoonWhileMakingANonwovenMat) {
  // A mat of 19 000 fibers (the limit is 20 000), each placed against all before it: 15 s to make
  // on the shared 2-core machine, unpolled, so Ctrl-C 2 s in once ended the run 16 s later
  // (2026-12-05). verify's plan does not make the mat, so 2 s in is the run's own making.
  const fs::path dir = fresh_test_dir();
  std::ofstream(dir / "mat.json") << R"({"pattern": "nonwoven", "tile-mm": 3.7})";
  const auto r = interrupt_after(spawn_weft({"verify", "--quality", "draft", "--threads", "2",
                                             "--weave", "mat.json", "--quiet", "-o", "report"},
                                            dir),
                                 2.0);
  expect_stopped(r, dir, dir / "report", "verify");
}

// Whether weft verify has begun its report: the staging folder beside the output exists
// (atomic_file.h names it ".tmp-<stem>-...").
bool report_staging_exists(const fs::path& dir, const std::string& stem) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(".tmp-" + stem, 0) == 0) return true;
  return false;
}

TEST(CliCancel, VerifyStopsSoonWhileRenderingItsReport) {
  // The report's renders (the patches and the fiber-level renders) come after every poll of the
  // run; they did not poll, nor did anything after them: Ctrl-C 0.3 s into the report once let the
  // renders, previews and plots finish and wrote the whole report, exit 0, 15 s later
  // (2026-12-05). A draft run is about 12 s before its report; a publication render alone takes
  // minutes.
  const fs::path dir = fresh_test_dir();
  const auto r = interrupt_after(
      spawn_weft({"verify", "--quality", "draft", "--threads", "2", "--quiet", "-o", "report"},
                 dir),
      0.3, 600, [&] { return report_staging_exists(dir, "report"); });
  expect_stopped(r, dir, dir / "report", "verify");
}

// Whether a process runs the plot script with 'dir' in its arguments (a verify report's staging
// folder lies in the test's own folder).
bool plot_script_running(const fs::path& dir, const std::string& script) {
  std::error_code ec;  // a process may end while it is listed
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    const std::string args((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (args.find(script) != std::string::npos && args.find(dir.string()) != std::string::npos)
      return true;
  }
  return false;
}

TEST(CliCancel, VerifyStopsSoonWhileDrawingItsPlots) {
  // A SIGINT sent to weft alone (not to its process group, as a terminal's Ctrl-C is) while the
  // plot script ran was lost: system() ignores SIGINT in its caller, and the report was then
  // finished and written, exit 0 (2026-12-06). The script now runs in a process group of its own
  // which weft ends on its own poll.
  const fs::path dir = fresh_test_dir();
  const auto r = interrupt_after(
      spawn_weft({"verify", "--quality", "draft", "--threads", "2", "--quiet", "-o", "report"},
                 dir),
      0.2, 600, [&] { return plot_script_running(dir, "plot_verify.py"); });
  expect_stopped(r, dir, dir / "report", "verify");
  EXPECT_FALSE(plot_script_running(dir, "plot_verify.py"));
}

// weft compare --plot sent 'signal' while its plot script draws: the script runs in a process
// group of its own (core/child_process.h), which compare ends on its own poll: exit 130, no plot,
// the script gone.
void expect_compare_plot_stopped_by(int signal) {
  const fs::path dir = fresh_test_dir();
  const fs::path a = flat_fiber_table(dir), b = dir / "b.exr";
  fs::copy_file(a, b);
  const auto r = interrupt_after(
      spawn_weft({"compare", a.string(), b.string(), "--plot", (dir / "curves.png").string()}, dir),
      0.2, 120, [&] { return plot_script_running(dir, "plot_compare.py"); }, signal);
  expect_stopped(r, dir, dir / "curves.png", "compare");
  EXPECT_FALSE(plot_script_running(dir, "plot_compare.py"));
}

TEST(CliCancel, CompareStopsSoonWhileDrawingItsPlot) {
  expect_compare_plot_stopped_by(SIGINT);
}

// A batch scheduler's stop (scancel, a time limit, `timeout`) is SIGTERM: weft once died at once
// and left its plot script running. It now stops as on Ctrl-C.
TEST(CliCancel, SigtermStopsAsCtrlCDoesAndEndsThePlotScript) {
  expect_compare_plot_stopped_by(SIGTERM);
}

TEST(CliCancel, FiberBakeStopsSoonAtHugePhotons) {
  const fs::path dir = fresh_test_dir();
  const auto r =
      interrupt_after(spawn_weft({"bake", "fiber", "white-cotton", "--photons", "100000000000",
                                  "--yes-long", "--resolution", "4", "--quiet", "-o", "fiber.exr"},
                                 dir),
                      1.0);
  expect_cancelled(r, dir, dir / "fiber.exr");
}

TEST(CliCancel, TimedRenderStopsSoonAtALargeImage) {
  // 4096 x 4096 with a time limit: 1.2 GB of running sums, once zeroed before the first poll.
  const fs::path dir = fresh_test_dir();
  const auto r = interrupt_after(
      spawn_weft({"render", (kExamples / "lambert-plane.json").string(), "--width", "4096",
                  "--height", "4096", "--time-limit", "1000", "--quiet", "-o", "out.exr"},
                 dir),
      1.0);
  expect_cancelled(r, dir, dir / "out.exr");
}

TEST(CliCancel, RenderStopsSoonWhileZeroingAHugeFilm) {
  // 16384 x 16384: 3.2 GB of film, once zeroed in one call before the first poll, which took 41 s
  // on the shared 2-core machine (2026-12-05); interrupted 1 s into it (the plan, reading one
  // small scene, is done well before, so the stop is the zeroing's own poll).
  const fs::path dir = fresh_test_dir();
  const auto r =
      interrupt_after(spawn_weft({"render", (kExamples / "lambert-plane.json").string(), "--width",
                                  "16384", "--height", "16384", "--quiet", "-o", "out.exr"},
                                 dir),
                      1.0);
  expect_cancelled(r, dir, dir / "out.exr");
}

TEST(CliCancel, SweepStopsSoonAtHugeSamples) {
  // 2^20 samples per pixel of each view's render.
  const fs::path dir = fresh_test_dir();
  const auto r = interrupt_after(
      spawn_weft({"sweep", (kExamples / "lambert-plane.json").string(), "--spp", "1048576",
                  "--resolution", "64", "--yes-long", "--quiet", "-o", "out.csv"},
                 dir),
      1.0);
  expect_cancelled(r, dir, dir / "out.csv");
}

TEST(CliCancel, SweepStopsSoonAtALargeResolution) {
  // 8192 x 8192 views: 3.5 GB of per-pixel sums for the sample's mask, once zeroed before the
  // view's render polled.
  const fs::path dir = fresh_test_dir();
  const auto r =
      interrupt_after(spawn_weft({"sweep", (kExamples / "lambert-plane.json").string(), "--spp",
                                  "1", "--resolution", "8192", "--quiet", "-o", "out.csv"},
                                 dir),
                      1.0);
  expect_cancelled(r, dir, dir / "out.csv");
}

TEST(CliCancel, CtrlCWhileReadingTheInputsExitsCleanly) {
  // A scene that never arrives (a named pipe no one writes: an input on a slow file system) keeps
  // the plan reading. Ctrl-C there once killed weft by the default action, the handler being
  // installed only where the work starts; now it is installed first thing, and the exit is 130.
  const fs::path dir = fresh_test_dir();
  ASSERT_EQ(mkfifo((dir / "scene.json").c_str(), 0600), 0);
  const auto r = interrupt_after(
      spawn_weft({"render", "scene.json", "--quiet", "-o", "out.exr"}, dir), 0.3, 10);
  const std::string err = slurp(dir / "stderr");
  EXPECT_LT(r.seconds_to_exit, kExitWithinSeconds) << err;
  expect_nothing_written(r, dir, dir / "out.exr");
  EXPECT_EQ(WEXITSTATUS(r.status), 130);
  EXPECT_NE(err.find(kInterruptedBeforeWork), std::string::npos) << err;
}

// Peak resident memory of the children waited for so far, bytes.
double children_peak_bytes() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return double(u.ru_maxrss) * 1024;
}

TEST(CliCancel, TimedRenderPeakIsWithinTwiceItsEstimate) {
  // The estimate the plan checks against --max-memory-gb (render_bytes: image and running sums)
  // against the peak resident size of a render that holds them: 1024 x 1024 with a time limit.
  // The scene and the program itself add a fixed part, measured on the same command at 16 x 16
  // and taken off, so that the per-pixel buffers are what is compared.
  const fs::path dir = fresh_test_dir();
  const auto peak_of = [&](int side) {
    const pid_t pid = fork();
    if (pid == 0) {
      // A child of its own, so that RUSAGE_CHILDREN is this render's alone.
      const int code = std::system(("cd '" + dir.string() + "' && '" + WEFT_EXE + "' render '" +
                                    (kExamples / "lambert-plane.json").string() + "' --width " +
                                    std::to_string(side) + " --height " + std::to_string(side) +
                                    " --time-limit 0.5 --quiet -o out.exr >/dev/null 2>err")
                                       .c_str());
      const double peak = children_peak_bytes();
      std::ofstream(dir / "peak") << peak;
      _exit(code == 0 ? 0 : 1);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp(dir / "err");
    return std::stod(slurp(dir / "peak"));
  };
  const double base = peak_of(16), big = peak_of(1024);
  weft::RenderSettings s;
  s.width = s.height = 1024;
  s.time_limit_s = 0.5;
  const double estimate = weft::render_bytes(s, false, false);
  const double measured = big - base;
  EXPECT_GT(measured, estimate / 2) << "peak " << big << ", base " << base;
  EXPECT_LT(measured, estimate * 2) << "peak " << big << ", base " << base;
}

// CPU seconds (user and system) of the children waited for so far.
double children_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// "(24 s of CPU" / "(5 min of CPU" / "(1.2 h of CPU" in weft verify's estimate line, seconds.
double printed_cpu_seconds(const std::string& err) {
  const size_t end = err.find(" of CPU");
  const size_t open = err.rfind('(', end);
  if (end == std::string::npos || open == std::string::npos) return -1;
  std::istringstream in(err.substr(open + 1, end - open - 1));
  double v = -1;
  std::string unit;
  in >> v >> unit;
  return unit == "s" ? v : unit == "min" ? 60 * v : unit == "h" ? 3600 * v : -1;
}

TEST(CliCancel, VerifyDraftTimeOnAWifSampleIsWithinTwiceItsEstimate) {
  // The bundled plain draft tiled 6 x 6: 36 times its fibers, so that the sample's own cost
  // (making it, building its scene for every ray trace and render, slower rays: verify/plan.cpp
  // estimate_verify) is a good part of the run. The printed CPU time against the run's, user and
  // system; the 8452 draft's 325 s of CPU was once estimated at 24 s.
  const fs::path dir = fresh_test_dir();
  std::ofstream(dir / "weave.json")
      << R"({"wif": ")" << (fs::path(WEFT_SOURCE_DIR) / "scenes/data/wif/54235-plain.wif").string()
      << R"(", "repeats": [6, 6]})";
  const pid_t pid = fork();
  if (pid == 0) {
    // A child of its own, so that RUSAGE_CHILDREN is this run's alone.
    const int code = std::system(("cd '" + dir.string() + "' && '" + WEFT_EXE +
                                  "' verify --quality draft --threads 2 --weave weave.json "
                                  "-o report >/dev/null 2>err")
                                     .c_str());
    std::ofstream(dir / "cpu") << children_cpu_seconds();
    _exit(code == 0 ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string err = slurp(dir / "err");
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << err;
  const double estimate = printed_cpu_seconds(err), measured = std::stod(slurp(dir / "cpu"));
  ASSERT_GT(estimate, 0) << err;
  EXPECT_GT(measured, estimate / 2) << err;
  EXPECT_LT(measured, estimate * 2) << err;
}

// "its scene about 157 MB" / "about 3.3 GB" in weft verify's estimate line, bytes.
double printed_scene_bytes(const std::string& err) {
  const std::string key = "its scene about ";
  const size_t at = err.find(key);
  if (at == std::string::npos) return -1;
  std::istringstream in(err.substr(at + key.size()));
  double v = -1;
  std::string unit;
  in >> v >> unit;
  return unit == "MB" ? v * 1e6 : unit == "GB" ? v * 1e9 : -1;
}

TEST(CliCancel, ReadmeVerifyDraftEstimatesAreWithinTwiceTheMeasured) {
  // The README's main job (weft verify on the bundled poplin) at draft quality: the printed CPU
  // time against the run's (user and system) and the printed memory of its scene against the
  // run's peak resident size, each within a factor of 2. Measured (2026-12-06, /usr/bin/time, the
  // shared 2-core machine at load 10): 24 s printed against 31.5 s; 157 MB printed against a peak
  // of 181 MB (173 MiB).
  const fs::path dir = fresh_test_dir();
  const pid_t pid = fork();
  if (pid == 0) {
    // A child of its own, so that RUSAGE_CHILDREN is this run's alone.
    const int code = std::system(("cd '" + dir.string() + "' && '" + WEFT_EXE +
                                  "' verify --quality draft --threads 2 -o report >/dev/null 2>err")
                                     .c_str());
    std::ofstream(dir / "cpu") << children_cpu_seconds();
    std::ofstream(dir / "peak") << children_peak_bytes();
    _exit(code == 0 ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string err = slurp(dir / "err");
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << err;
  const double cpu = printed_cpu_seconds(err), measured_cpu = std::stod(slurp(dir / "cpu"));
  ASSERT_GT(cpu, 0) << err;
  EXPECT_GT(measured_cpu, cpu / 2) << err;
  EXPECT_LT(measured_cpu, cpu * 2) << err;
  const double bytes = printed_scene_bytes(err), peak = std::stod(slurp(dir / "peak"));
  ASSERT_GT(bytes, 0) << err;
  EXPECT_GT(peak, bytes / 2) << err;
  EXPECT_LT(peak, bytes * 2) << err;
}

}  // namespace
