#include "raytrace_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/fiber/fiber_table_bake.h"

namespace weft::raytrace {

void check_fiber_energy(const TabulatedBsdfTable& t, const std::string& field) {
  const std::vector<double> a = t.total_albedo();
  for (size_t c = 0; c < a.size(); ++c)
    if (!(a[c] <= 1 + kFiberAlbedoAllowance)) {
      char v[32];
      std::snprintf(v, sizeof v, "%.4g", a[c]);
      throw Error("", field,
                  std::string("the fiber table's total albedo is ") + v + " in channel " +
                      std::to_string(c) +
                      ": a fiber sends out at most the light that hits it (at most 1, the bake's "
                      "exit fraction); bake it with weft bake fiber" +
                      (t.channels == 3 ? std::string(" (a saturated colour's RGB table can exceed "
                                                     "1: --bands spectral keeps it as it is)")
                                       : std::string()));
    }
}

void check_fiber_stand_in(const TabulatedBsdfTable& t, int resolution, int channels,
                          const std::string& field, const char* mismatch) {
  t.validate("");
  if (t.kind != "fiber" || t.resolution != resolution || t.channels != channels)
    throw Error("", field, mismatch);
  check_fiber_energy(t, field);
}

void check_proposal(const TabulatedBsdfTable& proposal, const TabulatedBsdfTable& fiber) {
  check_fiber_stand_in(proposal, fiber.resolution, fiber.channels, "proposal",
                       "the proposal must be a fiber table of the traced table's resolution and "
                       "channels");
}

void add_task(const Tally& t, int nc, CellSums& sums, FabricRaytraceResult& result) {
  for (const auto& e : t.exits)
    for (int c = 0; c < nc; ++c) {
      const double x = t.weights[e.first + c];
      sums.sum[e.cell * nc + c] += x;
      sums.sum2[e.cell * nc + c] += x * x;
    }
  for (const auto& [a, b] : t.books) result.bin_books[a].add(b);
}

void tabulate(const CellSums& sums, const CellSums& exact, const DirectionGrid& grid, int nc,
              uint64_t per_bin, const std::vector<uint64_t>& units, FabricRaytraceResult& result) {
  TabulatedBsdfTable& table = result.table;
  const int bins = grid.bins();
  const auto areas = grid.cosine_weighted_areas();
  table.resolution = grid.resolution;
  table.channels = nc;
  table.kind = "fabric";
  table.values.assign(static_cast<size_t>(bins) * bins * nc, 0.0f);
  const double n = static_cast<double>(per_bin);
  const double omega = grid.bin_solid_angle();
  result.standard_error.assign(table.values.size(), 0.0f);
  for (int a = 0; a < bins; ++a) {
    const double u = static_cast<double>(units[a]);
    std::vector<double>& noise2 = result.bin_books[a].noise2;
    std::vector<double>& signal2 = result.bin_books[a].signal2;
    noise2.assign(nc, 0.0);
    signal2.assign(nc, 0.0);
    for (int b = 0; b < bins; ++b) {
      const size_t cell = static_cast<size_t>(a) * bins + b;
      const double scale = omega / (n * areas[a] * areas[b]);
      const double w = areas[a] * areas[b];
      for (int c = 0; c < nc; ++c) {
        const size_t v = cell * nc + c;
        const double exact_sum = exact.sum.empty() ? 0.0 : exact.sum[cell];
        const double f = (sums.sum[v] + exact_sum) * scale;
        table.values[v] = static_cast<float>(f);
        // Per sample unit (a particle, or a launch block) the sum of its weights in the cell:
        // their sample variance.
        const double m1 = sums.sum[v] / u;
        double se = std::sqrt(std::max(0.0, sums.sum2[v] / u - m1 * m1) / u) * u * scale;
        // The exact part's variance, independent of the particles' (its own streams).
        if (!exact.sum2.empty() && exact.sum2[cell] > 0)
          se = std::sqrt(se * se + exact.sum2[cell] * scale * scale);
        result.standard_error[v] = static_cast<float>(se);
        noise2[c] += se * se * w;
        signal2[c] += f * f * w;
      }
    }
  }
  // Weights that overflow mean a fiber table that returns more light than it receives at every
  // crossing (a baked table conserves energy over the whole fiber): refuse it, not a table of inf.
  for (float v : table.values)
    if (!std::isfinite(v))
      throw Error("", "fiber",
                  "the ray trace's path weights overflowed: the fiber table returns more light "
                  "than it receives along paths (its albedo at B' plus B'' stays above 1); bake "
                  "it with weft bake fiber");
}

void describe(const WovenSample& sample, const TabulatedBsdfTable& fiber,
              const FabricRaytraceOptions& o, TabulatedBsdfTable& table) {
  table.metadata = {
      {"method", "raytrace"},
      {"estimator_revision", std::to_string(kFabricRaytraceRevision)},
      {"fiber_checksum", fiber.checksum()},
      {"particles_per_bin", std::to_string(o.particles_per_bin)},
      {"seed", std::to_string(o.seed)},
      {"estimator",
       o.next_event_rays > 0 ? "nee" : name_of(kChannelSamplingNames, o.channel_sampling)},
      {"sample", sample.summary.source + " (" + sample.summary.detail + ")"}};
  if (o.proposal) table.metadata["proposal_checksum"] = o.proposal->checksum();
  if (o.next_event_rays > 0) table.metadata["next_event_rays"] = std::to_string(o.next_event_rays);
  if (o.launch_lattice > 1) table.metadata["launch_lattice"] = std::to_string(o.launch_lattice);
  if (o.straight_through != StraightThrough::sampled)
    table.metadata["straight_through"] = name_of(kStraightThroughNames, o.straight_through);
  if (o.sheen_h_resolution > 0 && o.sheen_light != SheenLight::first_surface)
    table.metadata["sheen_light"] = name_of(kSheenLightNames, o.sheen_light);
  if (const auto& n = o.narrow_light) {  // its row is that light's, not the bin's beam's
    char text[96];
    std::snprintf(text, sizeof text, "theta %g, azimuth %g, half angle %g deg", n->theta_deg,
                  n->azimuth_deg, n->half_angle_deg);
    table.metadata["narrow_light"] = text;
  }
  // A table of paths cut short says so (only then, so that other tables keep their bytes).
  if (o.max_scatterings != FabricRaytraceOptions{}.max_scatterings)
    table.metadata["max_scatterings"] = std::to_string(o.max_scatterings);
  if (o.channel_sampling != ChannelSampling::mean) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, o.split_threshold).ptr;
    table.metadata["split_threshold"] = std::string(text, end);
    table.metadata["max_copies_per_particle"] = std::to_string(o.max_copies_per_particle);
  }
  for (const char* key : {"spec_hash", "spec_name"})
    if (const auto it = fiber.metadata.find(key); it != fiber.metadata.end())
      table.metadata[std::string("fiber_") + key] = it->second;
}

void describe_per_yarn(const FiberTables& f, TabulatedBsdfTable& table) {
  std::string list;
  for (size_t k = 0; k < f.tables.size(); ++k) {
    const TabulatedBsdfTable& t = *f.tables[k];
    if (k) list += "; ";
    list += (f.names.empty() ? std::to_string(k) : f.names[k]) + ": " + t.checksum();
    if (const auto it = t.metadata.find("spec_name"); it != t.metadata.end())
      list += " (" + it->second + ")";
  }
  table.metadata.erase("fiber_checksum");
  table.metadata.erase("fiber_spec_hash");
  table.metadata.erase("fiber_spec_name");
  table.metadata["fiber_tables"] = list;
  auto joined = [](const std::vector<int>& v) {
    std::string out;
    for (size_t i = 0; i < v.size(); ++i) {
      if (i) out += ',';
      out += std::to_string(v[i]);
    }
    return out;
  };
  if (!f.table_of_yarn.empty()) {
    std::vector<int> yarns(f.tables.size(), 0);
    for (int k : f.table_of_yarn) ++yarns[k];
    table.metadata["fiber_yarns_per_table"] = joined(yarns);
  }
  if (!f.table_of_mesh.empty()) table.metadata["fiber_table_of_mesh"] = joined(f.table_of_mesh);
}

void check_sheen_trace(const FabricRaytraceOptions& o, int bins, bool exact_lobe, bool record) {
  if (!exact_lobe)
    throw Error("", "sheen_h_resolution",
                "books the fibers' surface lobe: it needs fiber detail, one fiber table with an "
                "analytic surface lobe (weft bake fiber --surface-lobe analytic) and no proposal");
  if (o.first_bin != 0 || (o.bin_count != 0 && o.bin_count != bins))
    throw Error("", "sheen_h_resolution",
                "is booked for a whole table only: not with --shard or --resume");
  if (record) throw Error("", "sheen_h_resolution", "is not kept in recorded paths");
}

void add_booked_sheen(const CellSums& sums, const std::vector<uint64_t>& per_stratum, int threads,
                      HalfVectorLobe sheen, TabulatedBsdfTable& table) {
  const size_t first = table.values.size(), nc = static_cast<size_t>(sheen.channels);
  const size_t per_slot = static_cast<size_t>(sheen.window_bins()) * nc;
  const std::vector<double> projection = sheen.mean_projections(threads);
  for (size_t k = 0; k < sheen.values.size(); ++k) {
    const double m = projection[k / nc];
    const double n = static_cast<double>(per_stratum[k / per_slot % per_stratum.size()]);
    sheen.values[k] =
        m > 0 ? static_cast<float>(sums.sum[first + k] / (n * sheen.window_bin_solid_angle() * m))
              : 0.0f;
  }
  table.add_sheen(std::move(sheen), threads);
}

LightPlane::LightPlane(const NarrowLight& l) : light(l) {
  const double t = deg_to_rad(l.theta_deg), a = deg_to_rad(l.azimuth_deg);
  wi = {std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
  u = {std::cos(a), std::sin(a), 0};
  v = {-std::sin(a), std::cos(a), 0};
}

Vec3 LightPlane::draw(Rng& rng) const {
  const double c = 1 - rng.uniform() * (1 - std::cos(deg_to_rad(light.half_angle_deg)));
  const double s = std::sqrt(std::max(0.0, 1 - c * c)), p = 2 * kPi * rng.uniform();
  // e1 completes (e1, v, wi): the light's zenith tilted down the plane.
  const double t = deg_to_rad(light.theta_deg);
  const Vec3 e1 = u * std::cos(t) - Vec3{0, 0, std::sin(t)};
  return normalize(wi * c + e1 * (s * std::cos(p)) + v * (s * std::sin(p)));
}

int LightPlane::bin_of(const Vec3& wo, double& factor) const {
  if (!(wo.z > 0)) return -1;
  const double along = std::clamp(dot(wo, u), -1.0, 1.0);
  const double theta = std::asin(along), phi = std::atan2(dot(wo, v), wo.z);
  if (!(std::abs(phi) <= 0.5 * deg_to_rad(light.band_deg))) return -1;
  const double x = (rad_to_deg(theta) + NarrowLight::kMaxPlaneDeg) / light.bin_deg;
  if (!(x >= 0 && x < light.plane_bins())) return -1;
  factor = 1 / (wo.z * std::sqrt(1 - along * along));
  return static_cast<int>(x);
}

void tabulate_plane(const CellSums& sums, size_t first_value, const LightPlane& plane, int nc,
                    double launched, uint64_t units, FabricRaytraceResult& result) {
  const size_t n = static_cast<size_t>(plane.light.plane_bins()) * nc;
  const double scale =
      1 / (launched * deg_to_rad(plane.light.bin_deg) * deg_to_rad(plane.light.band_deg));
  const double u = static_cast<double>(units);
  result.plane_f.assign(n, 0.0);
  result.plane_f_se.assign(n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const double s = sums.sum[first_value + k], m1 = s / u;
    result.plane_f[k] = s * scale;
    result.plane_f_se[k] =
        std::sqrt(std::max(0.0, sums.sum2[first_value + k] / u - m1 * m1) * u) * scale;
  }
}

}  // namespace weft::raytrace
