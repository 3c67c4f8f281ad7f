#include "weft/fiber/fiber_spec.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "embedded_json.h"
#include "weft/core/error.h"
#include "weft/core/hash.h"
#include "weft/core/params.h"

namespace weft {

namespace {

using nlohmann::json;

std::string fmt(double v) {
  return ParamReader::fmt(v);
}

// A number, 33 band values, or {"points": [[nm, value], ...]} linearly interpolated.
Spectrum spectral(ParamReader& parent, const std::string& key) {
  const json& j = parent.at(key);
  const std::string path = parent.field(key);
  const std::string& file = parent.file();
  Spectrum s{};
  auto number = [&](const json& v, const std::string& at) {
    return parent.check_number(v, at, -1e300, 1e300);
  };
  if (j.is_number()) {
    s.fill(number(j, path));
    return s;
  }
  if (j.is_array()) {
    if (j.size() != static_cast<size_t>(kNumBands))
      throw Error(file, path,
                  "an array must hold 33 values (390..710 nm in 10 nm steps), got " +
                      std::to_string(j.size()));
    for (int b = 0; b < kNumBands; ++b) s[b] = number(j[b], path + "[" + std::to_string(b) + "]");
    return s;
  }
  if (j.is_object()) {
    ParamReader obj(j, file, path);
    const json& pts = obj.at("points");
    obj.finish();
    const std::string pp = path + ".points";
    if (!pts.is_array() || pts.size() < 2)
      throw Error(file, pp, "must be an array of at least two [wavelength_nm, value] pairs");
    std::vector<double> wl, val;
    for (size_t i = 0; i < pts.size(); ++i) {
      const std::string ip = pp + "[" + std::to_string(i) + "]";
      if (!pts[i].is_array() || pts[i].size() != 2)
        throw Error(file, ip, "must be a [wavelength_nm, value] pair");
      wl.push_back(number(pts[i][0], ip + "[0]"));
      val.push_back(number(pts[i][1], ip + "[1]"));
      if (i > 0 && !(wl[i] > wl[i - 1]))
        throw Error(file, ip, "wavelengths must increase strictly");
    }
    const double first = band_wavelength_nm(0), last = band_wavelength_nm(kNumBands - 1);
    if (wl.front() > first || wl.back() < last)
      throw Error(file, pp,
                  "points must cover " + fmt(first) + "-" + fmt(last) + " nm (given " +
                      fmt(wl.front()) + "-" + fmt(wl.back()) + " nm); no extrapolation");
    for (int b = 0; b < kNumBands; ++b) {
      const double w = band_wavelength_nm(b);
      size_t i = 0;
      while (i + 2 < wl.size() && wl[i + 1] < w) ++i;
      const double t = (w - wl[i]) / (wl[i + 1] - wl[i]);
      s[b] = (1 - t) * val[i] + t * val[i + 1];
    }
    return s;
  }
  throw Error(file, path, "must be a number, an array of 33 band values or {\"points\": ...}");
}

void require_range(const Spectrum& s, const ParamReader& p, const std::string& key, double lo,
                   bool lo_open, const char* what, double hi = 1e300) {
  for (int b = 0; b < kNumBands; ++b) {
    const bool bad = (lo_open ? !(s[b] > lo) : !(s[b] >= lo)) || !(s[b] <= hi);
    if (bad)
      throw Error(p.file(), p.field(key),
                  std::string(what) + " at " + fmt(band_wavelength_nm(b)) + " nm is " + fmt(s[b]) +
                      (hi < 1e300 ? " (must lie in " + std::string(lo_open ? "(" : "[") + fmt(lo) +
                                        ", " + fmt(hi) + "])"
                                  : ""));
  }
}

SizeDistribution parse_size(ParamReader p, double fiber_radius_um) {
  const std::string kind = p.choice("distribution", "", {"monodisperse", "lognormal"});
  const double max_um = kMaxParticleShareOfFiberRadius * fiber_radius_um;
  SizeDistribution d;
  if (kind == "monodisperse") {
    d = SizeDistribution::monodisperse(p.number("radius_um", 1e-300, max_um));
  } else {
    const double sigma = p.number("sigma", 1e-300, kMaxLognormalSigma);
    const double median = p.number("median_radius_um", 1e-300, 1e300);
    const double volume_median = median * std::exp(3 * sigma * sigma);
    if (volume_median > max_um)
      throw Error(p.file(), p.field("median_radius_um"),
                  "gives a volume-weighted median radius of " + fmt(volume_median) +
                      " um (median x exp(3 sigma^2)), above half the fiber radius (" + fmt(max_um) +
                      " um): particles that large are not a scattering medium");
    d = SizeDistribution::lognormal(median, sigma);
  }
  p.finish();
  return d;
}

// host.dyes: the recipe, each dye bundled and named once. The spec's density_g_cm3 must be
// read first: a recipe needs it.
void parse_dyes(ParamReader& host, FiberSpec& spec) {
  const std::string& file = host.file();
  if (!host.has("dyes")) return;
  if (spec.density_g_cm3 <= 0)
    throw Error(file, "density_g_cm3",
                "is required with a dye recipe (host.dyes): it turns percent on the weight of "
                "fibre into mol/L");
  const json& dyes = host.at("dyes");
  const std::string path = host.field("dyes");
  if (!dyes.is_array() || dyes.empty()) throw Error(file, path, "must be a non-empty array");
  if (dyes.size() > static_cast<size_t>(kMaxDyeComponents))
    throw Error(file, path,
                "lists " + std::to_string(dyes.size()) + " dyes, more than " +
                    std::to_string(kMaxDyeComponents));
  for (size_t i = 0; i < dyes.size(); ++i) {
    ParamReader d(dyes[i], file, path + "[" + std::to_string(i) + "]");
    DyeComponent c;
    c.dye = d.string("dye");
    (void)bundled_dye(c.dye, file, d.field("dye"));
    for (const auto& other : spec.dyes)
      if (other.dye == c.dye) throw Error(file, d.field("dye"), "'" + c.dye + "' is listed twice");
    c.concentration_owf_percent = d.number("concentration_owf_percent", 0, kMaxDyeOwfPercent);
    c.uptake_fraction = d.number("uptake_fraction", 1.0, 1e-300, 1.0);
    d.finish();
    spec.dyes.push_back(c);
  }
}

json spectrum_json(const Spectrum& s) {
  return json(std::vector<double>(s.begin(), s.end()));
}

}  // namespace

FiberSpec parse_fiber_spec(const std::string& json_text, const std::string& file) {
  const json root = parse_json(json_text, file);
  ParamReader p(root, file, "");
  FiberSpec spec;
  spec.name = p.string("name");
  if (p.has("notes")) {
    if (!p.at("notes").is_string()) throw Error(file, "notes", "must be a string");
  }
  spec.fiber_radius_um = p.number("fiber_radius_um", kMinFiberRadiusUm, kMaxFiberRadiusUm);

  ParamReader rough = p.object("roughness");
  spec.roughness_distribution = rough.choice("distribution", "", {"beckmann", "ggx"}) == "ggx"
                                    ? MicrofacetModel::kGgx
                                    : MicrofacetModel::kBeckmann;
  spec.roughness_alpha = rough.number("alpha", 1e-300, 1.0);
  rough.finish();

  if (p.has("density_g_cm3"))
    spec.density_g_cm3 = p.number("density_g_cm3", kMinFiberDensityGcm3, kMaxFiberDensityGcm3);
  ParamReader host = p.object("host");
  spec.host_n = spectral(host, "n");
  require_range(spec.host_n, host, "n", kMinHostIndex, false, "refractive index", kMaxHostIndex);
  const bool per_um = host.has("absorption_per_um"), per_mm = host.has("absorption_per_mm");
  if (per_um && per_mm)
    throw Error(file, "host", "give absorption_per_um or absorption_per_mm, not both");
  if (per_um) {
    spec.host_absorption_per_um = spectral(host, "absorption_per_um");
    require_range(spec.host_absorption_per_um, host, "absorption_per_um", 0.0, false, "absorption");
  } else if (per_mm) {
    const Spectrum mm = spectral(host, "absorption_per_mm");
    require_range(mm, host, "absorption_per_mm", 0.0, false, "absorption");
    for (int b = 0; b < kNumBands; ++b) spec.host_absorption_per_um[b] = mm[b] * 1e-3;
  }
  parse_dyes(host, spec);
  host.finish();

  const json& species = p.at("species");
  if (!species.is_array()) throw Error(file, "species", "must be an array");
  if (species.size() > static_cast<size_t>(kMaxSpecies))
    throw Error(file, "species",
                "lists " + std::to_string(species.size()) + " species, more than " +
                    std::to_string(kMaxSpecies) + " (each costs a Mie computation per band)");
  double total_fraction = 0;
  for (size_t i = 0; i < species.size(); ++i) {
    ParamReader s(species[i], file, "species[" + std::to_string(i) + "]");
    ParticleSpecies sp;
    sp.name = s.string("name");
    sp.n = spectral(s, "n");
    require_range(sp.n, s, "n", 0.0, true, "refractive index", kMaxParticleIndex);
    sp.k = spectral(s, "k");
    require_range(sp.k, s, "k", 0.0, false, "extinction coefficient k", kMaxParticleK);
    sp.volume_fraction = s.number("volume_fraction", 0.0, kMaxVolumeFraction);
    sp.size = parse_size(s.object("size"), spec.fiber_radius_um);
    s.finish();
    total_fraction += sp.volume_fraction;
    spec.species.push_back(std::move(sp));
  }
  spec.boundary =
      p.choice("boundary", "smooth", {"smooth", "rough-dielectric"}) == "rough-dielectric"
          ? FiberBoundary::kRoughDielectric
          : FiberBoundary::kSmooth;
  p.finish();
  if (total_fraction > kMaxVolumeFraction)
    throw Error(
        file, "species",
        "volume fractions add up to " + fmt(total_fraction) + ", above " + fmt(kMaxVolumeFraction));
  return spec;
}

Spectrum host_total_absorption_per_um(const FiberSpec& spec) {
  Spectrum total = spec.host_absorption_per_um;
  const Spectrum dyes = recipe_absorption_per_um(spec.dyes, spec.density_g_cm3);
  for (int b = 0; b < kNumBands; ++b) total[b] += dyes[b];
  return total;
}

const char* fiber_boundary_name(FiberBoundary boundary) {
  return boundary == FiberBoundary::kRoughDielectric ? "rough-dielectric" : "smooth";
}

std::vector<std::string> fiber_preset_names() {
  std::vector<std::string> names;
  for (int i = 0; i < detail::kNumFiberPresets; ++i)
    names.emplace_back(detail::kFiberPresets[i].name);
  return names;
}

const std::string& fiber_preset_json(const std::string& name) {
  // Built once from immutable compiled-in text.
  static const std::vector<std::pair<std::string, std::string>> presets = [] {
    std::vector<std::pair<std::string, std::string>> v;
    for (int i = 0; i < detail::kNumFiberPresets; ++i)
      v.emplace_back(detail::kFiberPresets[i].name, detail::kFiberPresets[i].json);
    return v;
  }();
  for (const auto& [n, text] : presets)
    if (n == name) return text;
  std::string list;
  for (const auto& [n, text] : presets) list += (list.empty() ? "" : ", ") + n;
  throw Error("", "preset", "unknown preset '" + name + "' (presets: " + list + ")");
}

FiberSpec load_fiber_spec(const std::string& path_or_preset) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(path_or_preset, ec)) {
    std::ifstream in(path_or_preset, std::ios::binary);
    if (!in) throw Error(path_or_preset, "", "cannot open file");
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_fiber_spec(ss.str(), path_or_preset);
  }
  for (const auto& name : fiber_preset_names())
    if (name == path_or_preset) return parse_fiber_spec(fiber_preset_json(name), "preset:" + name);
  std::string list;
  for (const auto& name : fiber_preset_names()) list += (list.empty() ? "" : ", ") + name;
  if (fs::exists(path_or_preset, ec)) throw Error(path_or_preset, "", "not a regular file");
  throw Error(path_or_preset, "", "no such file, and not a preset name (presets: " + list + ")");
}

std::string canonical_json(const FiberSpec& spec) {
  json j;
  j["format"] = "weft-fiber-spec-1";
  j["fiber_radius_um"] = spec.fiber_radius_um;
  j["roughness"] = {{"distribution", microfacet_model_name(spec.roughness_distribution)},
                    {"alpha", spec.roughness_alpha}};
  j["host"] = {{"n", spectrum_json(spec.host_n)},
               {"absorption_per_um", spectrum_json(spec.host_absorption_per_um)}};
  json species = json::array();
  for (const auto& s : spec.species) {
    json size;
    if (s.size.kind == SizeDistribution::Kind::kMonodisperse)
      size = {{"distribution", "monodisperse"}, {"radius_um", s.size.radius_um}};
    else
      size = {{"distribution", "lognormal"},
              {"median_radius_um", s.size.radius_um},
              {"sigma", s.size.sigma}};
    species.push_back({{"n", spectrum_json(s.n)},
                       {"k", spectrum_json(s.k)},
                       {"volume_fraction", s.volume_fraction},
                       {"size", size}});
  }
  j["species"] = species;
  // Written only with a recipe, so specs without one keep their hashes. The resolved molar
  // absorption is hashed too: a change of a bundled dye's data changes the hash.
  if (!spec.dyes.empty()) {
    json dyes = json::array();
    for (const auto& c : spec.dyes)
      dyes.push_back({{"dye", c.dye},
                      {"mol_per_L", dye_mol_per_L(c, spec.density_g_cm3)},
                      {"epsilon_per_M_per_cm",
                       spectrum_json(bundled_dye(c.dye, "", "dye").epsilon_per_M_per_cm)}});
    j["host"]["dyes"] = dyes;
  }
  // Written only when not the default, so specs from before the option keep their hashes (and
  // their cached tables).
  if (spec.boundary != FiberBoundary::kSmooth) j["boundary"] = fiber_boundary_name(spec.boundary);
  return j.dump();  // nlohmann objects keep keys sorted; numbers print shortest round-trip
}

uint64_t fiber_spec_hash(const FiberSpec& spec) {
  return fnv1a64(canonical_json(spec));
}

std::string fiber_spec_hash_hex(const FiberSpec& spec) {
  return hex64(fiber_spec_hash(spec));
}

}  // namespace weft
