#include "weft/materials/registry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

#include "weft/core/error.h"
#include "weft/materials/fabric/fiber_table_bake.h"
#include "weft/materials/table_cache.h"

namespace weft {
namespace {

using Factory = std::function<Bsdf(const nlohmann::json&, const MaterialContext&)>;

std::string field_name(const MaterialContext& ctx, const std::string& key) {
  return ctx.field_prefix.empty() ? key : ctx.field_prefix + "." + key;
}

void reject_unknown_keys(const nlohmann::json& params, const std::vector<std::string>& allowed,
                         const MaterialContext& ctx) {
  if (!params.is_object()) throw Error(ctx.source_file, ctx.field_prefix, "must be a JSON object");
  for (const auto& [key, value] : params.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      throw Error(ctx.source_file, field_name(ctx, key), "unknown parameter");
  }
}

// A colour parameter: a number (grey) or an array of 3 numbers, each finite and in [lo, hi].
Rgb parse_rgb(const nlohmann::json& params, const std::string& key, Rgb fallback, double lo,
              double hi, const MaterialContext& ctx) {
  if (!params.contains(key)) return fallback;
  const auto& v = params.at(key);
  auto check = [&](const nlohmann::json& x) {
    if (!x.is_number()) throw Error(ctx.source_file, field_name(ctx, key), "must be a number");
    const double d = x.get<double>();
    if (!std::isfinite(d) || d < lo || d > hi)
      throw Error(ctx.source_file, field_name(ctx, key),
                  "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return d;
  };
  if (v.is_array()) {
    if (v.size() != 3) throw Error(ctx.source_file, field_name(ctx, key), "needs 3 components");
    return {check(v[0]), check(v[1]), check(v[2])};
  }
  return Rgb(check(v));
}

double parse_number(const nlohmann::json& params, const std::string& key, double fallback,
                    double lo, double hi, const MaterialContext& ctx) {
  if (!params.contains(key)) return fallback;
  const auto& v = params.at(key);
  if (!v.is_number()) throw Error(ctx.source_file, field_name(ctx, key), "must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < lo || d > hi)
    throw Error(
        ctx.source_file, field_name(ctx, key),
        "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + v.dump());
  return d;
}

std::string parse_string(const nlohmann::json& params, const std::string& key,
                         const MaterialContext& ctx) {
  const auto& v = params.at(key);
  if (!v.is_string() || v.get<std::string>().empty())
    throw Error(ctx.source_file, field_name(ctx, key), "must be a non-empty string");
  return v.get<std::string>();
}

// "distribution" plus "alpha" or "roughness" (alpha = roughness^2, the perceptual convention).
MicrofacetDistribution parse_microfacet(const nlohmann::json& p, const MaterialContext& ctx) {
  MicrofacetDistribution d;
  d.model = MicrofacetModel::kBeckmann;  // Cook and Torrance's own choice
  if (p.contains("distribution")) {
    const std::string name = parse_string(p, "distribution", ctx);
    if (name == "beckmann") {
      d.model = MicrofacetModel::kBeckmann;
    } else if (name == "ggx") {
      d.model = MicrofacetModel::kGgx;
    } else {
      throw Error(ctx.source_file, field_name(ctx, "distribution"),
                  "unknown distribution '" + name + "' (valid: beckmann, ggx)");
    }
  }
  if (p.contains("alpha") && p.contains("roughness"))
    throw Error(ctx.source_file, field_name(ctx, "roughness"),
                "give either alpha or roughness, not both");
  // Below 1e-3 the lobe is narrower than double-precision sampling resolves well.
  constexpr double kMinAlpha = 1e-3, kMaxAlpha = 1.0;
  d.alpha = 0.3;
  if (p.contains("alpha")) d.alpha = parse_number(p, "alpha", 0.3, kMinAlpha, kMaxAlpha, ctx);
  if (p.contains("roughness")) {
    const double r = parse_number(p, "roughness", 0.0, std::sqrt(kMinAlpha), 1.0, ctx);
    d.alpha = r * r;
  }
  return d;
}

double parse_ior(const nlohmann::json& p, const MaterialContext& ctx) {
  return parse_number(p, "ior", kCottonIor, 1.0, 4.0, ctx);
}

// A fiber table for a spec, baked on first use and kept in the bake cache under a name derived
// from everything that determines its bits (spec physics, resolution, photons, seed, format).
std::filesystem::path baked_fiber_table(const nlohmann::json& p, const MaterialContext& ctx) {
  const std::string spec_name = parse_string(p, "spec", ctx);
  std::filesystem::path spec_path = spec_name;
  if (spec_path.is_relative() && std::filesystem::exists(ctx.base_dir / spec_path))
    spec_path = ctx.base_dir / spec_path;
  FiberSpec spec;
  try {
    spec = load_fiber_spec(std::filesystem::exists(spec_path) ? spec_path.string() : spec_name);
  } catch (const Error& e) {
    throw Error(ctx.source_file, field_name(ctx, "spec"), e.what());
  }
  FiberTableBakeOptions o;
  o.spectral = false;
  const double resolution =
      parse_number(p, "resolution", 8, 2, TabulatedBsdfTable::kMaxResolution, ctx);
  if (resolution != std::floor(resolution))
    throw Error(ctx.source_file, field_name(ctx, "resolution"), "must be an integer");
  o.resolution = static_cast<int>(resolution);
  const double photons = parse_number(p, "photons", 100000, 1, 1e12, ctx);
  if (photons != std::floor(photons))
    throw Error(ctx.source_file, field_name(ctx, "photons"), "must be an integer");
  o.photons_per_band = static_cast<uint64_t>(photons);
  const double seed = parse_number(p, "seed", 1, 0, 9.0e15, ctx);
  if (seed != std::floor(seed))
    throw Error(ctx.source_file, field_name(ctx, "seed"), "must be an integer");
  o.seed = static_cast<uint64_t>(seed);
  const std::string key = canonical_json(spec) + "|R" + std::to_string(o.resolution) + "|N" +
                          std::to_string(o.photons_per_band) + "|S" + std::to_string(o.seed) +
                          "|P" + std::to_string(o.passes) + "|rgb|v" +
                          std::to_string(TabulatedBsdfTable::kFormatVersion);
  uint64_t h = 1469598103934665603ULL;  // FNV-1a 64
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ULL;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  const std::filesystem::path dir =
      ctx.bake_cache_dir.empty() ? ctx.base_dir / ".weft-cache" : ctx.bake_cache_dir;
  const std::filesystem::path file =
      dir / ("fiber-" + fiber_spec_hash_hex(spec) + "-" + hex + ".exr");
  if (std::filesystem::exists(file)) return file;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir.string(), "", "cannot create the bake cache folder: " + ec.message());
  FiberTableBakeResult r = bake_fiber_table(spec, o, ctx.progress);
  if (r.cancelled) throw Error(ctx.source_file, field_name(ctx, "spec"), "bake interrupted");
  r.table.metadata["cache_key"] = hex;
  r.table.write_exr(file);
  return file;
}

// fiber_table / fabric_table: the table file (relative to base_dir) or, for fiber tables, a fiber
// spec to bake on demand; its kind, tint and scale.
Bsdf make_table_bsdf(const nlohmann::json& p, const MaterialContext& ctx, const std::string& kind) {
  if (kind == "fiber")
    reject_unknown_keys(p, {"file", "spec", "resolution", "photons", "seed", "tint", "scale"}, ctx);
  else
    reject_unknown_keys(p, {"file", "tint", "scale"}, ctx);
  if (!p.contains("file") && !p.contains("spec"))
    throw Error(ctx.source_file, field_name(ctx, "file"),
                kind == "fiber"
                    ? "is required (a baked table), or give 'spec' (a fiber spec or preset "
                      "to bake on demand)"
                    : "is required");
  if (p.contains("file") && p.contains("spec"))
    throw Error(ctx.source_file, field_name(ctx, "spec"), "give either 'file' or 'spec', not both");
  if (!p.contains("spec"))
    for (const char* k : {"resolution", "photons", "seed"})
      if (p.contains(k))
        throw Error(ctx.source_file, field_name(ctx, k), "applies only with 'spec'");
  std::filesystem::path file = p.contains("spec")
                                   ? baked_fiber_table(p, ctx)
                                   : std::filesystem::path(parse_string(p, "file", ctx));
  if (file.is_relative()) file = ctx.base_dir / file;
  const Rgb tint = parse_rgb(p, "tint", Rgb(1.0), 0.0, 1.0, ctx);
  const double scale = parse_number(p, "scale", 1.0, 0.0, 10.0, ctx);
  std::shared_ptr<const TabulatedBsdfData> data;
  try {
    data = ctx.cache ? ctx.cache->tabulated(file) : load_tabulated_bsdf(file);
  } catch (const Error& e) {
    throw Error(ctx.source_file, field_name(ctx, "file"), e.what());
  }
  if (data->kind != kind)
    throw Error(ctx.source_file, field_name(ctx, "file"),
                file.string() + " holds a " + data->kind + " table, expected a " + kind + " table");
  return TabulatedBsdf{data, tint * scale};
}

const std::map<std::string, Factory>& factories() {
  static const std::map<std::string, Factory> table = {
      {"lambert",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         reject_unknown_keys(p, {"reflectance"}, ctx);
         return LambertBsdf{parse_rgb(p, "reflectance", Rgb(0.5), 0.0, 1.0, ctx)};
       }},
      {"cook_torrance",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         reject_unknown_keys(p, {"distribution", "alpha", "roughness", "ior", "tint"}, ctx);
         return CookTorranceBsdf{parse_microfacet(p, ctx), parse_ior(p, ctx),
                                 parse_rgb(p, "tint", Rgb(1.0), 0.0, 1.0, ctx)};
       }},
      {"classic_fiber",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         reject_unknown_keys(p, {"reflectance", "distribution", "alpha", "roughness", "ior"}, ctx);
         return ClassicFiberBsdf::create(parse_rgb(p, "reflectance", Rgb(0.5), 0.0, 1.0, ctx),
                                         parse_microfacet(p, ctx), parse_ior(p, ctx));
       }},
      {"fiber_table",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         return make_table_bsdf(p, ctx, "fiber");
       }},
      {"fabric_table",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         return make_table_bsdf(p, ctx, "fabric");
       }},
      {"measured_nbrdf",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         reject_unknown_keys(p, {"name", "file"}, ctx);
         if (p.contains("name") == p.contains("file"))
           throw Error(ctx.source_file, field_name(ctx, "name"),
                       "give exactly one of name (a bundled material) or file");
         std::filesystem::path file;
         const std::string key = p.contains("name") ? "name" : "file";
         try {
           if (key == "name") {
             file = find_measured_nbrdf(parse_string(p, "name", ctx));
           } else {
             file = parse_string(p, "file", ctx);
             if (file.is_relative()) file = ctx.base_dir / file;
           }
           auto net = ctx.cache ? ctx.cache->nbrdf(file)
                                : std::make_shared<const NbrdfNetwork>(NbrdfNetwork::load(file));
           return MeasuredNbrdfBsdf{std::move(net)};
         } catch (const Error& e) {
           throw Error(ctx.source_file, field_name(ctx, key), e.what());
         }
       }},
  };
  return table;
}

}  // namespace

std::vector<std::string> material_names() {
  std::vector<std::string> names;
  for (const auto& [name, f] : factories()) names.push_back(name);
  return names;
}

Bsdf make_bsdf(const std::string& type, const nlohmann::json& params, const MaterialContext& ctx) {
  const auto& table = factories();
  const auto it = table.find(type);
  if (it == table.end()) {
    std::string valid;
    for (const auto& n : material_names()) valid += (valid.empty() ? "" : ", ") + n;
    throw Error(ctx.source_file, field_name(ctx, "type"),
                "unknown material '" + type + "' (valid: " + valid + ")");
  }
  return it->second(params, ctx);
}

}  // namespace weft
