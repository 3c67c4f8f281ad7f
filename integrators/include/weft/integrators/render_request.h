#pragma once
// weft render's request and plan: what a user asks for (a front end binds these fields as they
// are), and the job it becomes once every rule, file, memory and time estimate is checked, before
// any work. The run is render_to_files (render_job.h) on the plan's description and job.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/run_limits.h"
#include "weft/integrators/render_job.h"
#include "weft/scenes/description.h"

namespace weft {

// What a plan shows as it goes, before any later check can fail (a front end prints them).
struct ScenePlanHooks {
  // The scene description, just loaded: its warnings, notes and lights.
  std::function<void(const SceneDescription&)> scene_loaded = [](const SceneDescription&) {};
  // A warning that does not stop the plan (an unreadable checkpoint).
  std::function<void(const std::string&)> warning = [](const std::string&) {};
};

// What a user asks of weft render. Paths are as given; empty strings and unset values are options
// not given (the scene's settings then apply).
struct RenderRequest {
  std::string scene;                 // scene description (.json)
  std::vector<std::string> defines;  // "KEY=VALUE" overrides of the description, in order
  std::string output;                // .exr, .png or .hdr
  std::string preview, mask, mask_object;
  std::string camera;      // glTF camera by name or index
  std::string aov;         // "albedo,normal": passes written beside the output
  std::string crop;        // "x0,x1,y0,y1"
  double exposure_ev = 0;  // the preview's, in stops
  std::optional<int> spp, width, height, max_depth;
  std::optional<uint64_t> seed;
  std::optional<double> time_limit_s;
  bool spectral = false;  // true: spectral whatever the scene says
  int threads = RenderSettings{}.threads;
  RunLimits limits;
};

struct RenderPlan {
  SceneDescription description;  // with the request's overrides and camera
  RenderJob job;
  std::vector<NamedPath> inputs;  // the files the render reads (scene_inputs)
};

// weft::Error naming the option (or the file and field) at fault, in this order: a mask without
// its object, a bad override, the scene, an unknown camera or pass, a bad crop, an output that is
// an input or unwritable, too little memory, work too long without limits.yes_long.
RenderPlan plan_render(const RenderRequest& request, const ScenePlanHooks& hooks = {});

}  // namespace weft
