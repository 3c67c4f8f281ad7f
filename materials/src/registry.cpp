#include "weft/materials/registry.h"

#include <cmath>
#include <functional>
#include <map>
#include <optional>

#include "weft/core/error.h"
#include "weft/materials/table_cache.h"

namespace weft {
namespace {

using Factory = std::function<Bsdf(ParamReader&, const MaterialContext&)>;

std::string field_name(const MaterialContext& ctx, const std::string& key) {
  return ctx.field_prefix.empty() ? key : ctx.field_prefix + "." + key;
}

// "distribution" plus "alpha" or "roughness" (alpha = roughness^2, the perceptual convention).
MicrofacetDistribution read_microfacet(ParamReader& p) {
  MicrofacetDistribution d;
  d.model = p.choice("distribution", "beckmann", {"beckmann", "ggx"}) == "ggx"
                ? MicrofacetModel::kGgx
                : MicrofacetModel::kBeckmann;  // Cook and Torrance's own choice
  if (p.has("alpha") && p.has("roughness"))
    throw Error(p.file(), p.field("roughness"), "give either alpha or roughness, not both");
  // Below 1e-3 the lobe is narrower than double-precision sampling resolves well.
  constexpr double kMinAlpha = 1e-3, kMaxAlpha = 1.0;
  d.alpha = p.number("alpha", 0.3, kMinAlpha, kMaxAlpha);
  if (p.has("roughness")) {
    const double r = p.number("roughness", std::sqrt(kMinAlpha), 1.0);
    d.alpha = r * r;
  }
  return d;
}

double read_ior(ParamReader& p) {
  return p.number("ior", kCottonIor, 1.0, 4.0);
}

// fabric_table's weave table and how it is used (weave_modulation.h TableWeave), or null when the
// material names none. Reads its keys before finish(); the file is loaded by load_weave.
struct WeaveParams {
  std::filesystem::path file;
  TableWeave settings;
};
std::optional<WeaveParams> read_weave_params(ParamReader& p, const MaterialContext& ctx,
                                             const std::string& kind) {
  if (kind != "fabric") {
    for (const char* k : {"weave", "level", "uv_metres", "weave_min_pixels"})
      p.reject_unused(k, "applies only to fabric_table (a weave of a fabric table)");
    return std::nullopt;
  }
  if (!p.has("weave")) {
    for (const char* k : {"level", "uv_metres", "weave_min_pixels"})
      p.reject_unused(k, "applies only with 'weave' (a weave table)");
    return std::nullopt;
  }
  WeaveParams w;
  w.file = p.string("weave");
  if (w.file.is_relative()) w.file = ctx.base_dir / w.file;
  w.settings.file = w.file.string();
  const std::string level = p.choice("level", "auto", {"auto", "weave", "table"});
  w.settings.level = level == "weave"   ? WeaveLevel::weave
                     : level == "table" ? WeaveLevel::table
                                        : WeaveLevel::automatic;
  // Metres per UV unit: from a micrometre to a kilometre per unit.
  w.settings.uv_metres = p.number("uv_metres", 1.0, 1e-6, 1e3);
  w.settings.min_pixels = p.number("weave_min_pixels", 4.0, 0.0, 1e6);
  return w;
}

// The weave loaded and checked against its fabric table.
std::shared_ptr<const TableWeave> load_table_weave(ParamReader& p, const MaterialContext& ctx,
                                                   WeaveParams w, const TabulatedBsdfData& table) {
  try {
    w.settings.modulation = ctx.cache ? ctx.cache->weave(w.file) : load_weave(w.file);
  } catch (const Error& e) {
    throw Error(p.file(), p.field("weave"), e.what());
  }
  const int table_channels = table.bands.empty() ? 3 : kNumBands;
  if (w.settings.modulation->table().channels != table_channels)
    throw Error(p.file(), p.field("weave"),
                w.file.string() + " has " +
                    std::to_string(w.settings.modulation->table().channels) +
                    " channels, its fabric table " + std::to_string(table_channels) +
                    " (a weave belongs to the table it was baked with)");
  // The ray trace records the table its weave modulates; a weave of another table would move the
  // weave level's mean away from the table level's.
  const auto& meta = w.settings.modulation->table().metadata;
  if (const auto it = meta.find("fabric_checksum");
      it != meta.end() && it->second != table.checksum)
    throw Error(p.file(), p.field("weave"),
                w.file.string() + " was baked with the fabric table of checksum " + it->second +
                    ", not this one (" + table.checksum +
                    "): a weave belongs to the table it was baked with");
  return std::make_shared<const TableWeave>(std::move(w.settings));
}

// fiber_table / fabric_table: the table file (relative to base_dir) or, for fiber tables, a fiber
// spec that the context's resolver bakes on demand; its tint and scale.
Bsdf make_table_bsdf(ParamReader& p, const MaterialContext& ctx, const std::string& kind) {
  const bool from_spec = kind == "fiber" && p.has("spec");
  const std::string key = from_spec ? "spec" : "file";
  if (from_spec && p.has("file"))
    throw Error(p.file(), p.field("spec"), "give either 'file' or 'spec', not both");
  std::filesystem::path file;
  if (from_spec) {
    if (!ctx.fiber_tables)
      throw Error(p.file(), p.field("spec"),
                  "baking a fiber table on demand is not available here; give a baked 'file'");
    file = ctx.fiber_tables(p, ctx);
  } else {
    if (!p.has("file"))
      throw Error(p.file(), p.field("file"),
                  kind == "fiber" ? "is required (a baked table), or give 'spec' (a fiber spec or "
                                    "preset to bake on demand)"
                                  : "is required");
    file = p.string("file");
    if (file.is_relative()) file = ctx.base_dir / file;
    if (kind == "fiber")
      for (const char* k : {"resolution", "photons", "seed"})
        p.reject_unused(k, "applies only with 'spec'");
  }
  const Rgb tint = p.rgb("tint", Rgb(1.0), 0.0, 1.0);
  const double scale = p.number("scale", 1.0, 0.0, 10.0);
  // An opaque Lambertian backing under the cloth (upholstery foam), fabric tables only.
  std::optional<Rgb> backing;
  if (kind == "fabric" && p.has("backing_reflectance")) {
    backing = p.rgb("backing_reflectance", 0.0, 1.0);
    if (!(backing->max_component() < 1))
      throw Error(p.file(), p.field("backing_reflectance"),
                  "must be below 1 in every component (a backing that reflects everything "
                  "would trap light between it and the cloth without loss)");
  }
  if (kind == "fiber")
    p.reject_unused("backing_reflectance", "applies only to fabric_table (a cloth on a backing)");
  // Fiber tables only: a fabric table's backing and albedos are those of the interpolated table.
  TableLookup lookup = TableLookup::bilinear, sampling = TableLookup::bilinear;
  if (kind == "fiber") {
    const std::string read = p.choice("interpolation", "bilinear", {"bilinear", "cell"});
    if (read == "cell") lookup = TableLookup::cell;
    // What the sampling density follows within a cell: by default what eval reads.
    if (p.choice("sampling", read, {"bilinear", "cell"}) == "cell") sampling = TableLookup::cell;
  } else {
    p.reject_unused("interpolation", "applies only to fiber_table");
    p.reject_unused("sampling", "applies only to fiber_table");
  }
  std::optional<WeaveParams> weave = read_weave_params(p, ctx, kind);
  p.finish();
  std::shared_ptr<const TabulatedBsdfData> data;
  try {
    data = ctx.cache ? ctx.cache->tabulated(file) : load_tabulated_bsdf(file);
  } catch (const Error& e) {
    throw Error(p.file(), p.field(key), e.what());
  }
  if (data->kind != kind)
    throw Error(p.file(), p.field(key),
                file.string() + " holds a " + data->kind + " table, expected a " + kind + " table");
  TabulatedBsdf bsdf{data, tint * scale, lookup};
  bsdf.sampling = sampling;
  if (weave) bsdf.weave = load_table_weave(p, ctx, std::move(*weave), *data);
  if (backing) {
    try {
      bsdf.backing = TableBacking::make(*data, bsdf.scale, *backing);
    } catch (const Error& e) {
      throw Error(p.file(), p.field("backing_reflectance"), e.what());
    }
  }
  return bsdf;
}

Bsdf make_measured(ParamReader& p, const MaterialContext& ctx) {
  if (p.has("name") == p.has("file"))
    throw Error(p.file(), p.field("name"), "give exactly one of name (a bundled material) or file");
  const std::string key = p.has("name") ? "name" : "file";
  std::filesystem::path file = p.string(key);
  p.finish();
  try {
    if (key == "name") {
      file = find_measured_nbrdf(file.string());
    } else if (file.is_relative()) {
      file = ctx.base_dir / file;
    }
    auto net = ctx.cache ? ctx.cache->nbrdf(file)
                         : std::make_shared<const NbrdfNetwork>(NbrdfNetwork::load(file));
    return MeasuredNbrdfBsdf{std::move(net)};
  } catch (const Error& e) {
    throw Error(p.file(), p.field(key), e.what());
  }
}

// Factories that read every key they use and then call finish().
template <class Make>
Factory simple(Make make) {
  return [make](ParamReader& p, const MaterialContext&) -> Bsdf {
    Bsdf b = make(p);
    p.finish();
    return b;
  };
}

const std::map<std::string, Factory>& factories() {
  static const std::map<std::string, Factory> table = {
      {"lambert", simple([](ParamReader& p) -> Bsdf {
         return LambertBsdf{p.rgb("reflectance", Rgb(0.5), 0.0, 1.0)};
       })},
      {"cook_torrance", simple([](ParamReader& p) -> Bsdf {
         const MicrofacetDistribution d = read_microfacet(p);
         const double ior = read_ior(p);
         return CookTorranceBsdf{d, ior, p.rgb("tint", Rgb(1.0), 0.0, 1.0)};
       })},
      {"classic_fiber", simple([](ParamReader& p) -> Bsdf {
         const Rgb reflectance = p.rgb("reflectance", Rgb(0.5), 0.0, 1.0);
         const MicrofacetDistribution d = read_microfacet(p);
         return ClassicFiberBsdf::create(reflectance, d, read_ior(p));
       })},
      {"fiber_table",
       [](ParamReader& p, const MaterialContext& ctx) { return make_table_bsdf(p, ctx, "fiber"); }},
      {"fabric_table",
       [](ParamReader& p, const MaterialContext& ctx) {
         return make_table_bsdf(p, ctx, "fabric");
       }},
      {"measured_nbrdf", make_measured},
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
  ParamReader reader(params, ctx.source_file, ctx.field_prefix);
  return it->second(reader, ctx);
}

}  // namespace weft
