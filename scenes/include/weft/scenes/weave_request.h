#pragma once
// weft weave's request, plan and run: what a user asks for (a front end binds these fields as they
// are), the options it becomes once its rules are checked (sizes per direction or for both, one
// of each pair of alternatives, the legacy patch's options alone), and the run that builds and
// writes the sample. The run prints nothing.
#include <cstddef>
#include <optional>
#include <string>

#include "weft/core/run_limits.h"
#include "weft/scenes/weave.h"

namespace weft {

// What a user asks of weft weave. Unset values are options not given: they come from the sample
// description, else from the bundled sample (or a WIF draft's sizes).
struct WeaveRequest {
  WeaveOptions options;                // over the sample description's
  std::optional<std::string> sample;   // sample description (.json)
  std::optional<std::string> repeats;  // "N" or "NxM" (x by z)
  // Both directions' size at once, instead of --warp-<size>-mm / --weft-<size>-mm.
  std::optional<double> yarn_width_mm, yarn_thickness_mm;
  // The legacy open-mesh patch (WeaveParams): any of these asks for it, with the pattern and
  // sides of 'options'.
  std::optional<int> yarns, segments;
  std::optional<double> yarn_radius_mm, spacing_mm, amplitude_mm;
  std::string output;  // .gltf or .glb
  RunLimits limits;
};

struct WeavePlan {
  std::string output;
  std::optional<WeaveParams> legacy;  // the legacy patch, when asked for
  WeaveOptions options;  // the sample's otherwise: the description's with the request's
};

// weft::Error naming the option (without its dashes) at fault: a sample option with the legacy
// patch's, a bad --repeats, --yarn-<size>-mm with a per-direction size, both of a pair of
// alternatives, an unreadable sample description, an output that is an input or unwritable.
WeavePlan plan_weave(const WeaveRequest& request);

struct WeaveOutcome {
  std::optional<WeaveSummary> summary;  // the sample's (none for the legacy patch)
  size_t legacy_triangles = 0, legacy_vertices = 0;
};

// Builds the sample (or the legacy patch) and writes it to the plan's output.
WeaveOutcome run_weave(const WeavePlan& plan);

}  // namespace weft
