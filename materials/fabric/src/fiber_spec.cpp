#include "weft/materials/fabric/fiber_spec.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/hash.h"

namespace weft {
namespace detail {
// Generated at configure time from materials/fabric/presets/*.json (see materials/CMakeLists.txt).
struct FiberPresetText {
  const char* name;
  const char* json;
};
extern const FiberPresetText kFiberPresets[];
extern const int kNumFiberPresets;
}  // namespace detail

namespace {

using nlohmann::json;

std::string join_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

void check_keys(const json& j, const std::string& file, const std::string& path,
                std::initializer_list<const char*> allowed) {
  if (!j.is_object()) throw Error(file, path.empty() ? "(root)" : path, "must be a JSON object");
  for (const auto& [key, value] : j.items()) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      throw Error(file, join_path(path, key), "unknown key (allowed here: " + list + ")");
    }
  }
}

const json& require(const json& j, const std::string& file, const std::string& path,
                    const char* key) {
  const auto it = j.find(key);
  if (it == j.end()) throw Error(file, join_path(path, key), "missing");
  return *it;
}

double number(const json& j, const std::string& file, const std::string& path) {
  if (!j.is_number()) throw Error(file, path, "must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw Error(file, path, "must be finite");
  return v;
}

std::string text(const json& j, const std::string& file, const std::string& path) {
  if (!j.is_string()) throw Error(file, path, "must be a string");
  return j.get<std::string>();
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A number, 33 band values, or {"points": [[nm, value], ...]} linearly interpolated.
Spectrum spectral(const json& j, const std::string& file, const std::string& path) {
  Spectrum s{};
  if (j.is_number()) {
    s.fill(number(j, file, path));
    return s;
  }
  if (j.is_array()) {
    if (j.size() != static_cast<size_t>(kNumBands))
      throw Error(file, path,
                  "an array must hold 33 values (390..710 nm in 10 nm steps), got " +
                      std::to_string(j.size()));
    for (int b = 0; b < kNumBands; ++b)
      s[b] = number(j[b], file, path + "[" + std::to_string(b) + "]");
    return s;
  }
  if (j.is_object()) {
    check_keys(j, file, path, {"points"});
    const json& pts = require(j, file, path, "points");
    const std::string pp = path + ".points";
    if (!pts.is_array() || pts.size() < 2)
      throw Error(file, pp, "must be an array of at least two [wavelength_nm, value] pairs");
    std::vector<double> wl, val;
    for (size_t i = 0; i < pts.size(); ++i) {
      const std::string ip = pp + "[" + std::to_string(i) + "]";
      if (!pts[i].is_array() || pts[i].size() != 2)
        throw Error(file, ip, "must be a [wavelength_nm, value] pair");
      wl.push_back(number(pts[i][0], file, ip + "[0]"));
      val.push_back(number(pts[i][1], file, ip + "[1]"));
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

void require_range(const Spectrum& s, const std::string& file, const std::string& path, double lo,
                   bool lo_open, const char* what) {
  for (int b = 0; b < kNumBands; ++b) {
    const bool bad = lo_open ? !(s[b] > lo) : !(s[b] >= lo);
    if (bad)
      throw Error(file, path,
                  std::string(what) + " at " + fmt(band_wavelength_nm(b)) + " nm is " + fmt(s[b]));
  }
}

SizeDistribution parse_size(const json& j, const std::string& file, const std::string& path) {
  if (!j.is_object()) throw Error(file, path, "must be a JSON object");
  const std::string kind =
      text(require(j, file, path, "distribution"), file, join_path(path, "distribution"));
  SizeDistribution d;
  if (kind == "monodisperse") {
    check_keys(j, file, path, {"distribution", "radius_um"});
    d = SizeDistribution::monodisperse(
        number(require(j, file, path, "radius_um"), file, join_path(path, "radius_um")));
    if (!(d.radius_um > 0)) throw Error(file, join_path(path, "radius_um"), "must be > 0");
  } else if (kind == "lognormal") {
    check_keys(j, file, path, {"distribution", "median_radius_um", "sigma"});
    d = SizeDistribution::lognormal(
        number(require(j, file, path, "median_radius_um"), file,
               join_path(path, "median_radius_um")),
        number(require(j, file, path, "sigma"), file, join_path(path, "sigma")));
    if (!(d.radius_um > 0)) throw Error(file, join_path(path, "median_radius_um"), "must be > 0");
    if (!(d.sigma > 0) || d.sigma > kMaxLognormalSigma)
      throw Error(file, join_path(path, "sigma"),
                  "must lie in (0, " + fmt(kMaxLognormalSigma) + "] (standard deviation of ln r)");
  } else {
    throw Error(file, join_path(path, "distribution"),
                "unknown distribution '" + kind + "' (monodisperse, lognormal)");
  }
  return d;
}

json spectrum_json(const Spectrum& s) {
  return json(std::vector<double>(s.begin(), s.end()));
}

}  // namespace

FiberSpec parse_fiber_spec(const std::string& json_text, const std::string& file) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {
    throw Error(file, "", std::string("invalid JSON: ") + e.what());
  }
  check_keys(root, file, "", {"name", "fiber_radius_um", "roughness", "host", "species", "notes"});
  FiberSpec spec;
  spec.name = text(require(root, file, "", "name"), file, "name");
  if (spec.name.empty()) throw Error(file, "name", "must not be empty");
  if (const auto it = root.find("notes"); it != root.end()) text(*it, file, "notes");

  spec.fiber_radius_um =
      number(require(root, file, "", "fiber_radius_um"), file, "fiber_radius_um");
  if (!(spec.fiber_radius_um > 0)) throw Error(file, "fiber_radius_um", "must be > 0");

  const json& rough = require(root, file, "", "roughness");
  check_keys(rough, file, "roughness", {"distribution", "alpha"});
  const std::string dist =
      text(require(rough, file, "roughness", "distribution"), file, "roughness.distribution");
  if (dist == "beckmann")
    spec.roughness_distribution = MicrofacetModel::kBeckmann;
  else if (dist == "ggx")
    spec.roughness_distribution = MicrofacetModel::kGgx;
  else
    throw Error(file, "roughness.distribution", "unknown '" + dist + "' (beckmann, ggx)");
  spec.roughness_alpha =
      number(require(rough, file, "roughness", "alpha"), file, "roughness.alpha");
  if (!(spec.roughness_alpha > 0) || spec.roughness_alpha > 1)
    throw Error(file, "roughness.alpha", "must lie in (0, 1]");

  const json& host = require(root, file, "", "host");
  check_keys(host, file, "host", {"n", "absorption_per_um", "absorption_per_mm"});
  spec.host_n = spectral(require(host, file, "host", "n"), file, "host.n");
  require_range(spec.host_n, file, "host.n", 0.0, true, "refractive index");
  const bool per_um = host.contains("absorption_per_um"),
             per_mm = host.contains("absorption_per_mm");
  if (per_um && per_mm)
    throw Error(file, "host", "give absorption_per_um or absorption_per_mm, not both");
  if (per_um) {
    spec.host_absorption_per_um =
        spectral(host.at("absorption_per_um"), file, "host.absorption_per_um");
    require_range(spec.host_absorption_per_um, file, "host.absorption_per_um", 0.0, false,
                  "absorption");
  } else if (per_mm) {
    const Spectrum mm = spectral(host.at("absorption_per_mm"), file, "host.absorption_per_mm");
    require_range(mm, file, "host.absorption_per_mm", 0.0, false, "absorption");
    for (int b = 0; b < kNumBands; ++b) spec.host_absorption_per_um[b] = mm[b] * 1e-3;
  }

  const json& species = require(root, file, "", "species");
  if (!species.is_array()) throw Error(file, "species", "must be an array");
  double total_fraction = 0;
  for (size_t i = 0; i < species.size(); ++i) {
    const std::string p = "species[" + std::to_string(i) + "]";
    const json& s = species[i];
    check_keys(s, file, p, {"name", "n", "k", "volume_fraction", "size"});
    ParticleSpecies sp;
    sp.name = text(require(s, file, p, "name"), file, p + ".name");
    sp.n = spectral(require(s, file, p, "n"), file, p + ".n");
    require_range(sp.n, file, p + ".n", 0.0, true, "refractive index");
    sp.k = spectral(require(s, file, p, "k"), file, p + ".k");
    require_range(sp.k, file, p + ".k", 0.0, false, "extinction coefficient k");
    sp.volume_fraction =
        number(require(s, file, p, "volume_fraction"), file, p + ".volume_fraction");
    if (sp.volume_fraction < 0 || sp.volume_fraction > kMaxVolumeFraction)
      throw Error(
          file, p + ".volume_fraction",
          "must lie in [0, " + fmt(kMaxVolumeFraction) + "], got " + fmt(sp.volume_fraction));
    sp.size = parse_size(require(s, file, p, "size"), file, p + ".size");
    total_fraction += sp.volume_fraction;
    spec.species.push_back(std::move(sp));
  }
  if (total_fraction > kMaxVolumeFraction)
    throw Error(
        file, "species",
        "volume fractions add up to " + fmt(total_fraction) + ", above " + fmt(kMaxVolumeFraction));
  return spec;
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
  return j.dump();  // nlohmann objects keep keys sorted; numbers print shortest round-trip
}

uint64_t fiber_spec_hash(const FiberSpec& spec) {
  return fnv1a64(canonical_json(spec));
}

std::string fiber_spec_hash_hex(const FiberSpec& spec) {
  return hex64(fiber_spec_hash(spec));
}

}  // namespace weft
