#include "weft/materials/registry.h"

#include <cmath>
#include <functional>
#include <map>

#include "weft/core/error.h"

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

const std::map<std::string, Factory>& factories() {
  static const std::map<std::string, Factory> table = {
      {"lambert",
       [](const nlohmann::json& p, const MaterialContext& ctx) -> Bsdf {
         reject_unknown_keys(p, {"reflectance"}, ctx);
         return LambertBsdf{parse_rgb(p, "reflectance", Rgb(0.5), 0.0, 1.0, ctx)};
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
