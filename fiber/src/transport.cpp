#include "weft/fiber/transport.h"

#include <string>

namespace weft {
namespace {
void require_non_negative(double v, const char* field) {
  if (!std::isfinite(v) || v < 0) throw Error("", field, "must be finite and >= 0");
}
void require_index(double v, const char* field) {
  if (!std::isfinite(v) || !(v >= 1e-6))
    throw Error("", field, "refractive index must be finite and >= 1e-6");
}
}  // namespace

void TransportMedium::validate() const {
  require_non_negative(mu_a, "mu_a");
  require_non_negative(mu_s, "mu_s");
  require_index(n, "n");
}

void TransportOptions::validate() const {
  if (mode != WeightMode::implicit_capture && mode != WeightMode::analog &&
      mode != WeightMode::absorption_weight)
    throw Error("", "mode", "unknown weight mode");
  if (!std::isfinite(roulette_threshold) || !(roulette_threshold >= 0) || roulette_threshold >= 1)
    throw Error("", "roulette_threshold", "must lie in [0, 1)");
  if (!(roulette_survival > 0 && roulette_survival <= 1))
    throw Error("", "roulette_survival", "must lie in (0, 1]");
  if (max_events == 0) throw Error("", "max_events", "must be >= 1");
  if (boundary_scatter && exit_reflectance)
    throw Error("", "boundary_scatter", "a rough boundary excludes exit_reflectance");
  if (expected_exits && boundary_scatter)
    throw Error("", "expected_exits",
                "next-event estimation of exits needs the smooth boundary (its transmittance is "
                "analytic), not a rough dielectric one");
  if (!(expected_exit_cutoff > 0 && expected_exit_cutoff < 1))
    throw Error("", "expected_exit_cutoff", "must lie in (0, 1)");
}

SlabGeometry::SlabGeometry(double thickness, double n_above, double n_below)
    : thickness_(thickness), n_above_(n_above), n_below_(n_below) {
  if (std::isnan(thickness) || !(thickness > 0))
    throw Error("", "thickness", "must be > 0 (or infinite for a semi-infinite medium)");
  require_index(n_above, "n_above");
  require_index(n_below, "n_below");
}

CylinderGeometry::CylinderGeometry(double radius, double n_outside)
    : radius_(radius), radius2_(radius * radius), inv_radius_(1 / radius), n_outside_(n_outside) {
  if (!std::isfinite(radius) || !(radius > 0) || !std::isfinite(radius2_) || !(radius2_ > 0))
    throw Error("", "radius", "must be finite and > 0");
  require_index(n_outside, "n_outside");
}

}  // namespace weft
