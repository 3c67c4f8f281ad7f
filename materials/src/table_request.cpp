#include "weft/materials/table_request.h"

#include <algorithm>

#include "weft/core/hash.h"
#include "weft/core/output_guard.h"
#include "weft/core/params.h"

namespace weft {

nlohmann::json table_info(const TabulatedBsdfTable& t, const std::string& file) {
  float lo = t.values.front(), hi = lo;
  for (float v : t.values) lo = std::min(lo, v), hi = std::max(hi, v);
  const DirectionGrid g = t.grid();
  // Light arriving along the normal (w_i = n), summed over all exits.
  const auto normal = t.directional_albedo(g.bin_of({0, 0, 1}));
  // Seen along the normal under uniform light (the renderer's reading; differs from the above
  // for a non-reciprocal table, e.g. the paper's summed fabric tables).
  const auto view = t.directional_albedo_seen_from(g.bin_of({0, 0, 1}));
  std::vector<double> albedo(t.channels);
  for (int c = 0; c < t.channels; ++c) albedo[c] = normal.total(c);
  nlohmann::json info = {{"file", file},
                         {"format_version", TabulatedBsdfTable::kFormatVersion},
                         {"resolution", t.resolution},
                         {"bins", g.bins()},
                         {"bands", t.bands()},
                         {"kind", t.kind},
                         {"metadata", t.metadata},
                         {"checksum", t.checksum()},
                         {"min_per_sr", lo},
                         {"max_per_sr", hi},
                         {"albedo_normal_incidence", albedo},
                         {"reflectance_normal_incidence", normal.reflectance},
                         {"transmittance_normal_incidence", normal.transmittance},
                         {"reflectance_normal_view", view.reflectance},
                         {"transmittance_normal_view", view.transmittance}};
  // The analytic lobe the cells include (surface_lobe.h), as the file names it.
  if (t.surface_lobe) info["surface_lobe"] = t.surface_lobe->attributes();
  // The sheen over half vectors the cells include (half_vector_lobe.h), as the file names it.
  if (t.sheen) info["sheen"] = t.sheen->attributes();
  return info;
}

TableBakePlan plan_table_bake(const TableBakeRequest& r) {
  const nlohmann::json params = parse_json(r.params, "--params");
  // Fail before the work, not after it; the files the parameters name (a table, a measured
  // network) are inputs.
  validate_output_paths(r.limits, {{r.output, "--output"}},
                        json_named_files(params, "--params file"));
  TabulatedBsdfTable::check_output_path(r.output, "--output");
  MaterialContext ctx;
  ctx.field_prefix = "--params";
  Bsdf bsdf = make_bsdf(r.type, params, ctx);
  return {r, params, std::move(bsdf)};
}

TabulatedBsdfTable run_table_bake(const TableBakePlan& p, const ProgressCallback& progress) {
  const TableBakeRequest& r = p.request;
  auto t = TabulatedBsdfTable::from_function(
      r.resolution, 3,
      [&](const Vec3& wo, const Vec3& wi, std::span<double> v) {
        const Rgb f = p.bsdf.eval(wo, wi);
        v[0] = f.r, v[1] = f.g, v[2] = f.b;
      },
      r.samples, r.seed, r.threads, progress);
  t.kind = r.kind;
  const std::string spec = r.type + " " + p.params.dump();
  t.metadata = {{"source", "analytic " + spec},
                {"spec_hash", hex64(fnv1a64(spec))},
                {"seed", std::to_string(r.seed)},
                {"samples_per_cell", std::to_string(r.samples)}};
  return t;
}

}  // namespace weft
