// weft mie: Mie efficiencies, g and amplitudes of a sphere (or a lognormal ensemble).
// weft medium: per-band scattering and absorption of a fiber spec or preset.
#include <cmath>
#include <complex>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/math.h"
#include "weft/core/spectrum.h"
#include "weft/fiber/medium.h"
#include "weft/fiber/mie.h"

namespace weft::cli {
namespace {

// Options arrive as text so that malformed and non-finite values are reported with the option's
// name, like every other input error. Ranges are the library's to check (mie.h): its errors name
// the field (m, x, particle_n, host_n, radius_um, wavelength_nm, size.sigma).
struct MieOptions {
  std::string m_re, m_im, x;
  std::string particle_n, particle_k, host_n, radius_um, wavelength_nm, sigma;
  std::string angles_deg;
  bool json = false;
};

std::optional<double> number(const std::string& text, const std::string& option) {
  if (text.empty()) return std::nullopt;
  if (const auto v = finite_number(text)) return v;
  throw Error("", option, "'" + text + "' is not a finite number");
}

double required(const std::optional<double>& v, const std::string& option) {
  if (!v) throw Error("", option, "is required here");
  return *v;
}

std::string format_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

nlohmann::json complex_parts(const std::vector<std::complex<double>>& s, bool imag) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& v : s) a.push_back(imag ? v.imag() : v.real());
  return a;
}

// Efficiencies and g, of one sphere (MieResult) or of an ensemble (MieEnsemble).
template <class Result>
void add_efficiencies(nlohmann::json& j, const Result& r) {
  j["qext"] = r.qext;
  j["qsca"] = r.qsca;
  j["qabs"] = r.qabs;
  j["qback"] = r.qback;
  j["g"] = r.g;
}

// One sphere's efficiencies, g, and (at the requested angles) amplitudes and phase function.
void add_sphere(nlohmann::json& j, const MieResult& res, const std::vector<double>& angles_deg) {
  add_efficiencies(j, res);
  j["terms"] = res.terms;
  if (angles_deg.empty()) return;
  j["angles_deg"] = angles_deg;
  j["s1_re"] = complex_parts(res.s1, false);
  j["s1_im"] = complex_parts(res.s1, true);
  j["s2_re"] = complex_parts(res.s2, false);
  j["s2_im"] = complex_parts(res.s2, true);
  j["phase_function_per_sr"] = mie_phase_function(res);
}

int run_mie(const MieOptions& o) {
  const auto m_re = number(o.m_re, "--m-re"), m_im = number(o.m_im, "--m-im");
  const auto x = number(o.x, "--x");
  const auto pn = number(o.particle_n, "--particle-n"), pk = number(o.particle_k, "--particle-k");
  const auto hn = number(o.host_n, "--host-n"), r = number(o.radius_um, "--radius-um");
  const auto wl = number(o.wavelength_nm, "--wavelength-nm");
  const auto sigma = number(o.sigma, "--lognormal-sigma");
  const bool relative = m_re || m_im || x;
  const bool physical = pn || pk || hn || r || wl || sigma;
  if (relative && physical) {
    const std::string first = m_re ? "--m-re" : m_im ? "--m-im" : "--x";
    const std::string second = pn   ? "--particle-n"
                               : pk ? "--particle-k"
                               : hn ? "--host-n"
                               : r  ? "--radius-um"
                               : wl ? "--wavelength-nm"
                                    : "--lognormal-sigma";
    throw Error("", second,
                "cannot be combined with " + first +
                    " (give m and x, or the particle, host, radius and wavelength)");
  }
  if (!relative && !physical)
    throw Error("", "--m-re",
                "give --m-re/--m-im/--x, or --particle-n/--host-n/--radius-um/--wavelength-nm");

  // Scattering angles are this command's input: the library sees only their cosines.
  std::vector<double> angles_deg, mu;
  if (!o.angles_deg.empty()) {
    angles_deg = parse_range(o.angles_deg, "--angles-deg");
    for (double a : angles_deg) {
      if (a < 0 || a > 180) throw Error("", "--angles-deg", "angles must lie in [0, 180] degrees");
      mu.push_back(std::cos(deg_to_rad(a)));
    }
  }

  nlohmann::json j;
  if (relative) {
    const std::complex<double> m(required(m_re, "--m-re"), m_im.value_or(0.0));
    const MieResult res = mie_sphere(m, required(x, "--x"), mu);
    j = {{"x", res.x}, {"m_re", m.real()}, {"m_im", m.imag()}};
    add_sphere(j, res, angles_deg);
  } else {
    const double n = required(pn, "--particle-n"), k = pk.value_or(0.0);
    const double h = required(hn, "--host-n"), radius = required(r, "--radius-um");
    const double lambda = required(wl, "--wavelength-nm");
    const double xv = mie_size_parameter(h, radius, lambda);
    j = {{"particle_n", n},         {"particle_k", k}, {"host_n", h},   {"radius_um", radius},
         {"wavelength_nm", lambda}, {"x", xv},         {"m_re", n / h}, {"m_im", k / h}};
    if (sigma) {
      const MieEnsemble e =
          mie_ensemble(n, k, h, SizeDistribution::lognormal(radius, *sigma), lambda, mu);
      j["distribution"] = "lognormal";
      j["sigma"] = *sigma;
      add_efficiencies(j, e);
      j["cext_um2"] = e.mean_cext_um2;
      j["csca_um2"] = e.mean_csca_um2;
      j["cabs_um2"] = e.mean_cabs_um2;
      j["mean_volume_um3"] = e.mean_volume_um3;
      if (!mu.empty()) {
        j["angles_deg"] = angles_deg;
        j["phase_function_per_sr"] = e.phase;
      }
    } else {
      const MieResult res = mie_sphere_physical(n, k, h, radius, lambda, mu);
      const double area = kPi * radius * radius;
      j["distribution"] = "monodisperse";
      add_sphere(j, res, angles_deg);
      j["cext_um2"] = res.qext * area;
      j["csca_um2"] = res.qsca * area;
      j["cabs_um2"] = res.qabs * area;
    }
  }

  if (o.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("x = %.10g  m = %.10g + %.10gi\n", j["x"].get<double>(), j["m_re"].get<double>(),
              j["m_im"].get<double>());
  std::printf("Q_ext = %.10g\nQ_sca = %.10g\nQ_abs = %.10g\nQ_back = %.10g\ng = %.10g\n",
              j["qext"].get<double>(), j["qsca"].get<double>(), j["qabs"].get<double>(),
              j["qback"].get<double>(), j["g"].get<double>());
  if (j.contains("csca_um2"))
    std::printf("C_ext = %.10g um^2\nC_sca = %.10g um^2\nC_abs = %.10g um^2\n",
                j["cext_um2"].get<double>(), j["csca_um2"].get<double>(),
                j["cabs_um2"].get<double>());
  if (j.contains("phase_function_per_sr")) {
    std::printf("%10s %16s\n", "angle_deg", "p (1/sr)");
    for (size_t i = 0; i < angles_deg.size(); ++i)
      std::printf("%10.4g %16.8g\n", angles_deg[i], j["phase_function_per_sr"][i].get<double>());
  }
  return 0;
}

struct MediumCliOptions {
  std::string spec;
  std::string wavelengths;
  int threads = 0;
  bool json = false, quiet = false;
};

int run_medium(const MediumCliOptions& o, const RunLimits& limits) {
  const FiberSpec spec = load_fiber_spec(o.spec);
  std::vector<int> bands;
  if (!o.wavelengths.empty()) {
    for (double w : parse_range(o.wavelengths, "--wavelengths-nm")) {
      const double b = (w - kFirstBandNm) / kBandStepNm;
      const long bi = std::lround(b);
      if (std::abs(b - bi) > 1e-9 || bi < 0 || bi >= kNumBands)
        throw Error("", "--wavelengths-nm",
                    "wavelength " + format_g(w) + " nm is not a band centre (390, 400, ..., 710)");
      bands.push_back(static_cast<int>(bi));
    }
  }
  if (o.threads < 0) throw Error("", "--threads", "must be >= 0");
  MediumOptions mo;
  mo.threads = o.threads;
  const FiberMedium m = build_fiber_medium(spec, bands, mo, progress_bar(limits, o.quiet));

  nlohmann::json out = {{"name", m.spec_name},
                        {"hash", m.spec_hash},
                        {"fiber_radius_um", m.fiber_radius_um},
                        {"roughness",
                         {{"distribution", microfacet_model_name(spec.roughness_distribution)},
                          {"alpha", spec.roughness_alpha}}}};
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& b : m.bands)
    arr.push_back({{"wavelength_nm", b.wavelength_nm},
                   {"host_n", b.host_n},
                   {"mu_s_per_um", b.mu_s_per_um},
                   {"mu_a_per_um", b.mu_a_per_um},
                   {"mu_a_host_per_um", b.mu_a_host_per_um},
                   {"mu_a_particles_per_um", b.mu_a_particles_per_um},
                   {"albedo", b.albedo},
                   {"g", b.g},
                   {"g_table", b.phase.mean_cosine()}});
  out["bands"] = arr;
  if (o.json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::printf("%s (hash %s), fiber radius %g um\n", m.spec_name.c_str(), m.spec_hash.c_str(),
              m.fiber_radius_um);
  std::printf("%6s %8s %12s %12s %8s %8s\n", "nm", "n_host", "mu_s/um", "mu_a/um", "albedo", "g");
  for (const auto& b : m.bands)
    std::printf("%6.0f %8.4f %12.6g %12.6g %8.5f %8.5f\n", b.wavelength_nm, b.host_n, b.mu_s_per_um,
                b.mu_a_per_um, b.albedo, b.g);
  return 0;
}

}  // namespace

void add_mie_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<MieOptions>();
  auto* sub = app.add_subcommand(
      "mie", "Mie efficiencies, g, amplitudes and phase function of a sphere (m = n + ik, k >= 0)");
  sub->add_option("--m-re", o->m_re, "real part of the relative index m");
  sub->add_option("--m-im", o->m_im, "imaginary part of m (>= 0 absorbing; default 0)");
  sub->add_option("--x", o->x, "size parameter 2 pi n_host r / lambda");
  sub->add_option("--particle-n", o->particle_n, "particle refractive index (real part)");
  sub->add_option("--particle-k", o->particle_k, "particle extinction coefficient k (default 0)");
  sub->add_option("--host-n", o->host_n, "host refractive index (real)");
  sub->add_option("--radius-um", o->radius_um, "sphere radius (lognormal: median radius), um");
  sub->add_option("--wavelength-nm", o->wavelength_nm, "vacuum wavelength, nm");
  sub->add_option("--lognormal-sigma", o->sigma,
                  "average over a lognormal size distribution with this sigma of ln r");
  sub->add_option("--angles-deg", o->angles_deg,
                  "scattering angles a:b:step or a,b,c (degrees) for S1, S2 and p(theta)");
  sub->add_flag("--json", o->json, "print JSON");
  commands.push_back({sub, [o](const RunLimits&) { return run_mie(*o); }});
}

void add_medium_command(CLI::App& app, Commands& commands) {
  auto o = std::make_shared<MediumCliOptions>();
  auto* sub = app.add_subcommand(
      "medium", "Per-band mu_s, mu_a, albedo and g of a fiber spec file or preset");
  sub->add_option("spec", o->spec, "spec file, or a preset (docs/presets.md)")->required();
  sub->add_option("--wavelengths-nm", o->wavelengths,
                  "band centres a:b:step or a,b,c (default all)");
  sub->add_option("--threads", o->threads, "threads (0 = all cores)");
  sub->add_flag("--json", o->json, "print JSON");
  sub->add_flag("--quiet", o->quiet, "no progress bar");
  commands.push_back({sub, [o](const RunLimits& l) { return run_medium(*o, l); }});
}

}  // namespace weft::cli
