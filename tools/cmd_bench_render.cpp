// weft bench render: Embree rtcIntersect1 throughput against the path tracer's on the same scene,
// and the path tracer's 1 -> 2 thread speed-up (the measurement is
// bench/include/weft/bench/render_bench.h). Without a scene: woven patches of ~65k and ~1M
// triangles from the weave generator.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "weft/bench/render_bench.h"
#include "weft/scenes/description.h"

namespace weft::cli {

void add_bench_render_command(CLI::App& bench, Commands& commands) {
  struct Options {
    std::string scene;
    bool json = false;
    RenderBenchOptions bench;
  };
  auto o = std::make_shared<Options>();
  auto* sub =
      bench.add_subcommand("render", "Embree vs path-tracer rays per second, and thread scaling");
  sub->add_option("scene", o->scene, "scene description (.json); default: generated woven patches");
  sub->add_option("--threads", o->bench.threads, "threads for the parallel runs")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  sub->add_option("--spp", o->bench.render.spp, "samples per pixel of the path-traced image")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  sub->add_option("--rays", o->bench.diffuse_rays, "diffuse rays for the Embree measurement")
      ->check(CLI::Range(1024, 1 << 26))
      ->capture_default_str();
  sub->add_option("--repeats", o->bench.repeats,
                  "times each measurement is made; figures are medians, the replay ratio with its "
                  "range")
      ->check(CLI::Range(1, kMaxBenchRepeats))
      ->capture_default_str();
  sub->add_flag("--json", o->json, "JSON output");
  commands.push_back(
      {sub, [o](const RunLimits&) {
         const RenderBenchOptions& opt = o->bench;
         std::vector<RenderBenchResult> results;
         if (!o->scene.empty()) {
           results.push_back(bench_render_scene(load_scene_description(o->scene), o->scene, opt));
         } else {
           WeaveParams small;  // 2 x 16 yarns x 128 x 8 x 2 = 65,536 triangles
           small.yarns = 16, small.segments = 128, small.sides = 8;
           WeaveParams large;  // 2 x 64 yarns x 256 x 16 x 2 = 1,048,576 triangles
           large.yarns = 64, large.segments = 256, large.sides = 16;
           results.push_back(bench_render_scene(weave_bench_scene(small), "weave-65k", opt));
           results.push_back(bench_render_scene(weave_bench_scene(large), "weave-1M", opt));
         }
         auto to_json = [&](const RenderBenchResult& r) {
           return nlohmann::json{{"name", r.name},
                                 {"triangles", r.triangles},
                                 {"threads", opt.threads},
                                 {"build_s", r.build_s},
                                 {"embree_rays_per_s", r.embree_rays_per_s},
                                 {"path_rays_per_s", r.path_rays_per_s},
                                 {"path_intersect_rays_per_s", r.path_intersect_rays_per_s},
                                 {"ratio", r.ratio},
                                 {"embree_replay_rays_per_s", r.embree_replay_rays_per_s},
                                 {"ratio_replay", r.ratio_replay},
                                 {"ratio_replay_min", r.ratio_replay_min},
                                 {"ratio_replay_max", r.ratio_replay_max},
                                 {"repeats", r.repeats},
                                 {"ray_packets", r.ray_packets},
                                 {"path_rays_per_s_one_by_one", r.path_rays_per_s_one_by_one},
                                 {"ratio_replay_one_by_one", r.ratio_replay_one_by_one},
                                 {"packet_gain", r.packet_gain},
                                 {"path_rays_per_s_1thread", r.path_rays_per_s_1thread},
                                 {"speedup", r.speedup},
                                 {"machine_speedup", r.machine_speedup}};
         };
         if (o->json) {
           // Top-level keys are the first scene's; every scene is under "scenes".
           nlohmann::json j = to_json(results.front());
           j["scenes"] = nlohmann::json::array();
           for (const auto& r : results) j["scenes"].push_back(to_json(r));
           std::cout << j.dump(2) << "\n";
         } else {
           for (const auto& r : results)
             std::printf(
                 "%-12s %9zu tris  embree %.3g rays/s  path %.3g rays/s  ratio %.2f  "
                 "replay ratio %.2f (%.2f-%.2f over %d; %.2f without packets, which buy "
                 "%.2fx)  speed-up 1->%d threads %.2fx (machine %.2fx)\n",
                 r.name.c_str(), r.triangles, r.embree_rays_per_s, r.path_rays_per_s, r.ratio,
                 r.ratio_replay, r.ratio_replay_min, r.ratio_replay_max, r.repeats,
                 r.ratio_replay_one_by_one, r.packet_gain, opt.threads, r.speedup,
                 r.machine_speedup);
         }
         return 0;
       }});
}

}  // namespace weft::cli
