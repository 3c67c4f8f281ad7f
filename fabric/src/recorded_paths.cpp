// The recorded paths' replay with another fiber table (recorded_paths.h). The recording and the
// re-weighted table are in fabric_raytrace.cpp, next to the trace whose steps they mirror.
#include "weft/fabric/recorded_paths.h"

#include "weft/fabric/raytrace_steps.h"

namespace weft::raytrace {

void replay_path_ops(const std::vector<PathOp>& ops, const TabulatedBsdfTable& fiber,
                     const LineAlbedo* tube, int channels, Tally& tally) {
  std::vector<std::vector<double>> pending;
  std::vector<double> w;
  size_t unit_first = 0;
  for (const PathOp& op : ops) {
    switch (op.kind) {
      case PathOp::launch:
        pending.clear();
        pending.emplace_back(static_cast<size_t>(channels), op.x);
        break;
      case PathOp::pop:
        w = std::move(pending.back());
        pending.pop_back();
        break;
      case PathOp::scatter:  // as weigh_scatter
        for (int c = 0; c < channels; ++c) w[c] *= fiber.at(static_cast<int>(op.a), op.b, c) / op.x;
        break;
      case PathOp::tube: {  // as weigh_as_round_fiber
        const int bins[2] = {static_cast<int>(op.a), op.b};
        scale_as_round_fiber(*tube, op.x, std::span<const int>(bins, op.b < 0 ? 1 : 2), w);
        break;
      }
      case PathOp::divide:  // as survives_roulette
        for (double& x : w) x /= op.x;
        break;
      case PathOp::split: {  // as split
        const int n = static_cast<int>(op.a);
        for (double& x : w) x /= n;
        for (int copy = 1; copy < n; ++copy) pending.push_back(w);
        break;
      }
      case PathOp::book:
        tally_exit(tally, unit_first, static_cast<uint64_t>(op.a), w);
        break;
      case PathOp::unit:
        unit_first = tally.exits.size();
        break;
    }
  }
}

}  // namespace weft::raytrace
